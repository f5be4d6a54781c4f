// `cairn softness` run as a process: the numbers it prints against the
// closed forms of constraints/softness.hpp, and bad input rejected with one
// line on stderr and exit status 2.
#include "cli_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>

namespace {

using cairn::test::CliResult;

CliResult softness(const std::string& args) {
  const cairn::test::TempDir tmp("cairn_softness");
  return cairn::test::runCairn("softness " + args, tmp);
}

// The `name = value ...` lines of the report.
std::map<std::string, double> values(const std::string& out) {
  std::map<std::string, double> v;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string name, eq, num;
    if (l >> name >> eq >> num && eq == "=") v[name] = num == "inf" ? INFINITY : std::stod(num);
  }
  return v;
}

void expectRel(const std::map<std::string, double>& v, const std::string& name, double expected) {
  ASSERT_TRUE(v.count(name)) << name << " not printed";
  EXPECT_NEAR(v.at(name), expected, 1e-10 * std::abs(expected)) << name;
}

constexpr double kPi = 3.14159265358979323846;

// ERP 0.2, CFM 1e-5 at h = 1/60 on 1 kg: k = ERP / (h CFM) = 1.2e6 N/m,
// c = (1 - ERP) / CFM = 8e4 N s/m, f = sqrt(k/m) / 2 pi, zeta = c / 2 sqrt(k m),
// and cairn's impulse-form diagonal term CFM / h = 6e-4 1/kg.
TEST(CliSoftness, ErpCfmPrintsTheClosedFormSpring) {
  const CliResult r = softness("--erp 0.2 --cfm 1e-5 --dt 1/60 --mass 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto v = values(r.out);
  expectRel(v, "stiffness", 1.2e6);
  expectRel(v, "damping", 8e4);
  expectRel(v, "frequency", std::sqrt(1.2e6) / (2 * kPi));
  expectRel(v, "damping_ratio", 8e4 / (2 * std::sqrt(1.2e6)));
  expectRel(v, "cfm_over_h", 1e-5 * 60);
}

// The mass scales f and zeta as 1/sqrt(m), not k and c.
TEST(CliSoftness, MassChangesFrequencyAndRatioOnly) {
  const auto v = values(softness("--erp 0.2 --cfm 1e-5 --dt 0.0166666666666666667 --mass 4").out);
  expectRel(v, "stiffness", 1.2e6);
  expectRel(v, "frequency", std::sqrt(1.2e6 / 4) / (2 * kPi));
  expectRel(v, "damping_ratio", 8e4 / (2 * std::sqrt(1.2e6 * 4)));
}

// ERP = h k / (h k + c), CFM = 1 / (h k + c): the inverse of the first test.
TEST(CliSoftness, StiffnessDampingPrintsErpCfm) {
  const CliResult r = softness("--stiffness 1.2e6 --damping 8e4 --dt 1/60");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto v = values(r.out);
  expectRel(v, "erp", 0.2);
  expectRel(v, "cfm", 1e-5);
  expectRel(v, "cfm_over_h", 6e-4);
  EXPECT_FALSE(v.count("frequency"));  // needs a mass

  const double k = 300, c = 7, h = 0.01, m = 2;
  const auto w = values(softness("--stiffness 300 --damping 7 --dt 0.01 --mass 2").out);
  expectRel(w, "erp", h * k / (h * k + c));
  expectRel(w, "cfm", 1 / (h * k + c));
  expectRel(w, "frequency", std::sqrt(k / m) / (2 * kPi));
  expectRel(w, "damping_ratio", c / (2 * std::sqrt(k * m)));
}

// k = m omega^2, c = 2 zeta m omega, then ERP and CFM from them.
TEST(CliSoftness, FrequencyDampingRatioPrintsErpCfmAndSpring) {
  const double f = 2, zeta = 0.5, m = 3, h = 0.01;
  const double w = 2 * kPi * f, k = m * w * w, c = 2 * zeta * m * w;
  const CliResult r = softness("--frequency 2 --damping-ratio 0.5 --mass 3 --dt 0.01");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto v = values(r.out);
  expectRel(v, "stiffness", k);
  expectRel(v, "damping", c);
  expectRel(v, "erp", h * k / (h * k + c));
  expectRel(v, "cfm", 1 / (h * k + c));
  expectRel(v, "cfm_over_h", 1 / (h * k + c) / h);
  expectRel(v, "frequency", f);
  expectRel(v, "damping_ratio", zeta);
}

TEST(CliSoftness, ZeroCfmIsRigid) {
  const CliResult r = softness("--erp 0.2 --cfm 0 --dt 1/60 --mass 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::isinf(values(r.out).at("stiffness")));
}

TEST(CliSoftness, BadInputIsOneLineOnStderrAndStatusTwo) {
  for (const char* args : {
           "--erp -0.1 --cfm 1e-5 --dt 1/60 --mass 1",   // negative
           "--erp 1.5 --cfm 1e-5 --dt 1/60 --mass 1",    // erp outside [0, 1]
           "--erp 0.2 --cfm -1e-5 --dt 1/60",            // negative cfm
           "--erp 0.2 --cfm 1e-5 --mass 1",              // missing dt
           "--erp 0.2 --cfm 1e-5 --dt 0",                // zero dt
           "--erp 0.2 --cfm 1e-5 --dt 1/0",              // infinite dt
           "--erp 0.2 --cfm 1e-5 --dt 1/60 --mass -1",   // negative mass
           "--erp 0.2 --cfm 1e-5 --dt 1/60 --mass 0",    // zero mass
           "--erp 0.2 --stiffness 100 --dt 1/60",        // mixed spellings
           "--cfm 1e-5 --frequency 2 --mass 1 --dt 0.01",
           "--stiffness 100 --damping-ratio 1 --dt 0.01",
           "--erp 0.2 --dt 1/60",                        // half a spelling
           "--damping-ratio 0.5 --mass 1 --dt 0.01",
           "--frequency 2 --dt 0.01",                    // frequency without mass
           "--frequency 0 --mass 1 --dt 0.01",
           "--stiffness -5 --dt 0.01",
           "--stiffness 0 --damping 0 --dt 0.01",        // a row that does nothing
           "--erp nan --cfm 1e-5 --dt 0.01",
           "--erp abc --cfm 1e-5 --dt 0.01",
           "--dt 0.01",                                  // no spelling at all
       }) {
    const CliResult r = softness(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(r.out, "") << args;
    ASSERT_FALSE(r.err.empty()) << args;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("cairn softness: ", 0), 0u) << r.err;
  }
}

}  // namespace
