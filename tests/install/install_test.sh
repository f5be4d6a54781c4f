#!/usr/bin/env bash
# Installs cairn from BUILD into a temporary prefix and builds an outside
# project against it from a temporary directory, twice: with CMake
# (find_package(cairn), cairn::cairn) and with pkg-config (cairn.pc). Checks
# that only the public headers were installed and that the library links
# none of Bullet, GoogleTest or CLI11.
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1"; src="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"
fail() { echo "FAIL: $*"; exit 1; }

cmake --install "$build" --prefix "$prefix" >/dev/null

# Only include/cairn/*.hpp: no internal header travels with the library.
diff <(cd "$src/include" && find cairn -type f | sort) <(cd "$prefix/include" && find cairn -type f | sort) \
  || fail "installed headers differ from include/cairn"
lib="$(find "$prefix" -name libcairn.a | head -1)"
[ -n "$lib" ] || fail "libcairn.a not installed"
[ -f "$(dirname "$lib")/cmake/cairn/cairnConfig.cmake" ] || fail "no CMake package"
[ -f "$(dirname "$lib")/pkgconfig/cairn.pc" ] || fail "no pkg-config file"
# The library neither calls nor names Bullet (bt*), GoogleTest (testing::)
# or CLI11 (CLI::), and its link interface lists none of them.
if nm -C -u "$lib" | grep -E ' (bt[A-Z]|testing::|CLI::)' | head -3 | grep -q .; then
  fail "libcairn.a references Bullet, GoogleTest or CLI11"
fi
if grep -riE 'bullet|gtest|cli11' "$(dirname "$lib")/cmake/cairn" "$(dirname "$lib")/pkgconfig/cairn.pc"; then
  fail "the installed package links Bullet, GoogleTest or CLI11"
fi

# CMake: an outside project in a temporary directory.
cp -r "$src/tests/install/consumer" "$tmp/app"
cmake -S "$tmp/app" -B "$tmp/app/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/app/build" >/dev/null
"$tmp/app/build/consumer" || fail "the CMake-built program failed its checks"

# pkg-config: the same program with a plain compiler command line.
flags="$(PKG_CONFIG_PATH="$(dirname "$lib")/pkgconfig" pkg-config --cflags --libs cairn)"
(cd "$tmp/app" && c++ -std=c++20 -O1 main.cpp $flags -o consumer_pc) || fail "pkg-config build failed"
"$tmp/app/consumer_pc" || fail "the pkg-config-built program failed its checks"
echo "install test passed"
