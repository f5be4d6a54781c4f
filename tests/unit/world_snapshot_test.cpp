// Snapshots (World::saveSnapshot, restoreSnapshot): a world restored into a
// fresh World continues bit-identically to the one that never stopped, and
// a snapshot of another version, truncated or corrupted is refused with an
// InputError that leaves the world as it was.
//
// Determinism is the invariant: the same state stepped the same way gives
// the same bits, so every comparison here is == (no tolerance), over every
// body's position, orientation and velocities and over the whole state as
// the snapshot format writes it.
#include "cairn/error.hpp"
#include "cairn/scene.hpp"
#include "cairn/world.hpp"
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"
#include "world/snapshot.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace cairn {
namespace {

void expectSameBodies(const World& a, const World& b) {
  const std::vector<BodyId> ids = a.bodies();
  ASSERT_EQ(ids, b.bodies());
  for (const BodyId id : ids) {
    const Transform ta = a.transform(id), tb = b.transform(id);
    EXPECT_TRUE(ta.p == tb.p && ta.q.coeffs() == tb.q.coeffs()) << a.name(id);
    EXPECT_TRUE(a.linearVelocity(id) == b.linearVelocity(id)) << a.name(id);
    EXPECT_TRUE(a.angularVelocity(id) == b.angularVelocity(id)) << a.name(id);
    EXPECT_EQ(a.isAsleep(id), b.isAsleep(id)) << a.name(id);
  }
}

// `first` steps (300), a snapshot, a fresh World restored from it, 300 more
// steps in each: the restored run must equal the straight run bit for bit.
void expectRestoredRunContinuesExactly(const SceneDesc& scene, int first = 300) {
  World straight = buildWorld(scene);
  for (int i = 0; i < first; ++i) straight.step(scene.dt);
  const std::vector<std::uint8_t> bytes = straight.saveSnapshot();
  World restored;
  restored.restoreSnapshot(bytes);
  EXPECT_EQ(restored.stepCount(), first);
  EXPECT_EQ(restored.time(), straight.time());
  EXPECT_EQ(restored.saveSnapshot(), bytes);  // the state read back is the state written
  for (int i = 0; i < 300; ++i) {
    straight.step(scene.dt);
    restored.step(scene.dt);
  }
  expectSameBodies(straight, restored);
  EXPECT_EQ(restored.saveSnapshot(), straight.saveSnapshot());  // contacts, warm starts, sleep, clock: all of it
}

TEST(WorldSnapshot, RestoredPile1000ContinuesBitIdentically) { expectRestoredRunContinuesExactly(scenarios::pile(10)); }
TEST(WorldSnapshot, RestoredRagdollContinuesBitIdentically) { expectRestoredRunContinuesExactly(scenarios::ragdoll()); }
TEST(WorldSnapshot, RestoredChain100ContinuesBitIdentically) { expectRestoredRunContinuesExactly(scenarios::chain(100)); }
// chain-20's joints pass 1 cm at step 22 and auto leaves PGS once they have
// not closed for 5 steps: a snapshot at step 24 holds a run of steps under
// way (world/method_choice.cpp), which the restored world must finish at
// the same step.
TEST(WorldSnapshot, RestoredChainInTheMiddleOfAJointDriftRunContinuesBitIdentically) {
  expectRestoredRunContinuesExactly(scenarios::chain(20), 24);
}

// A small world with a bit of everything: a hull, a mesh, a joint, a
// spring, a destroyed body (a dead slot and a free list), contacts.
World smallWorld() {
  World w;
  BodyDef ground;
  ground.name = "ground";
  ground.type = BodyType::Static;
  ground.shapes.push_back(ShapeDesc::plane(Vec3::UnitY(), 0));
  w.createBody(ground);
  const BodyId a = w.createBody(test::boxDef("a", Vec3(0, 0.5, 0)));
  const BodyId b = w.createBody(test::sphereDef("b", Vec3(0, 2, 0)));
  const BodyId gone = w.createBody(test::sphereDef("gone", Vec3(5, 2, 0)));
  JointDef j;
  j.name = "hinge";
  j.type = JointType::Hinge;
  j.body_a = a;
  j.body_b = b;
  j.anchor = Vec3(0, 1.25, 0);
  j.axis = Vec3::UnitZ();
  w.createJoint(j);
  SpringDef s;
  s.body_a = a;
  s.anchor_a = Vec3(0, 0.5, 0);
  s.anchor_b = Vec3(0, 4, 0);
  s.stiffness = 10;
  w.createSpring(s);
  w.destroyBody(gone);
  for (int i = 0; i < 30; ++i) w.step(1.0 / 60);
  return w;
}

void expectRefused(World& w, const std::vector<std::uint8_t>& bad, const std::string& field, const std::string& words) {
  const std::vector<std::uint8_t> before = w.saveSnapshot();
  try {
    w.restoreSnapshot(bad);
    FAIL() << "accepted a bad snapshot (" << words << ")";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
  EXPECT_EQ(w.saveSnapshot(), before);  // untouched
}

TEST(WorldSnapshot, AnotherVersionTruncatedOrCorruptedIsRefusedAndChangesNothing) {
  World source = smallWorld();
  const std::vector<std::uint8_t> good = source.saveSnapshot();
  World w = smallWorld();
  w.step(1.0 / 60);  // a different state, to see that it stays

  std::vector<std::uint8_t> version = good;
  version[8] = static_cast<std::uint8_t>(detail::kSnapshotVersion + 1);  // little-endian: the low byte
  expectRefused(w, version, "version",
                "snapshot format version " + std::to_string(detail::kSnapshotVersion + 1) + "; this cairn reads version " +
                    std::to_string(detail::kSnapshotVersion));
  std::vector<std::uint8_t> truncated(good.begin(), good.begin() + static_cast<long>(good.size() / 2));
  expectRefused(w, truncated, "payload", "truncated snapshot");
  expectRefused(w, std::vector<std::uint8_t>(good.begin(), good.begin() + 10), "header", "truncated snapshot");
  std::vector<std::uint8_t> flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  expectRefused(w, flipped, "checksum", "corrupted snapshot");
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  expectRefused(w, longer, "payload", "corrupted snapshot");
  const std::string text = "{\"bodies\": []}";
  expectRefused(w, std::vector<std::uint8_t>(text.begin(), text.end()), "magic", "not a cairn snapshot");
  // And the good one is accepted.
  w.restoreSnapshot(good);
  EXPECT_EQ(w.saveSnapshot(), good);
}

// With the checksum skipped (as the fuzz entry point does), every single-
// byte change of the payload either still reads as a consistent world or is
// refused with an InputError: nothing else escapes, nothing crashes.
TEST(WorldSnapshot, EveryByteFlipOfThePayloadIsReadOrRefusedCleanly) {
  const std::vector<std::uint8_t> good = smallWorld().saveSnapshot();
  int refused = 0, read = 0;
  for (size_t i = detail::kSnapshotHeaderSize; i < good.size(); ++i) {
    std::vector<std::uint8_t> bad = good;
    bad[i] ^= 0xff;
    try {
      (void)detail::decodeSnapshot(bad, "flipped", false);
      ++read;
    } catch (const InputError&) {
      ++refused;
    }
    EXPECT_EQ(detail::fuzzSnapshotInput(bad.data(), bad.size()), 0);
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(read, 0);  // most doubles take any bits
}

TEST(WorldSnapshot, FileRoundTripKeepsHandlesGenerationsAndCallbacks) {
  const auto dir = std::filesystem::temp_directory_path() / ("cairn_snapshot_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "small.snap").string();
  World a = smallWorld();
  a.saveSnapshot(path);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));

  World b;
  int callbacks = 0;
  b.setPreSolveCallback([&](ContactInfo&) { ++callbacks; });
  const BodyId stale{3, 0};  // "gone": destroyed before the snapshot
  b.restoreSnapshot(path);
  EXPECT_EQ(b.bodyCount(), 3);
  EXPECT_FALSE(b.isValid(stale));
  EXPECT_THROW(b.transform(stale), HandleError);
  EXPECT_TRUE(b.findJoint("hinge").isValid());
  // The next body reuses the dead slot with the next generation, as in the original.
  const BodyId next_a = a.createBody(test::sphereDef("new", Vec3(9, 1, 0)));
  const BodyId next_b = b.createBody(test::sphereDef("new", Vec3(9, 1, 0)));
  EXPECT_EQ(next_a, next_b);
  EXPECT_EQ(next_b.index, 3);
  b.step(1.0 / 60);
  EXPECT_GT(callbacks, 0);  // the callback set on b survived the restore

  EXPECT_THROW(b.restoreSnapshot((dir / "missing.snap").string()), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cairn
