// Internals of the Bullet oracle shared by validation/bullet_*.cpp: unit
// conversions, the shape and joint builders, and the row-softness plumbing
// that makes Bullet's joint rows use cairn's (ODE's) CFM convention.
//
// Nothing outside validation/bullet_*.cpp includes this header, so Bullet's
// headers stay out of the rest of the project.
#pragma once

#include "validation/bullet_oracle.hpp"
#include "cairn/defs.hpp"
#include "cairn/settings.hpp"

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h>

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace cairn::validation::detail {

inline btVector3 toBt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
inline btQuaternion toBt(const Quat& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
inline btTransform toBt(const Vec3& p, const Quat& q) { return btTransform(toBt(q), toBt(p)); }
inline Vec3 fromBt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
inline Quat fromBt(const btQuaternion& q) { return Quat(q.w(), q.x(), q.y(), q.z()); }

// A right-handed frame whose x axis is `x` (unit) and whose y axis is `y`
// (unit, perpendicular to x), placed at `origin`.
btTransform frameXY(const Vec3& origin, const Vec3& x, const Vec3& y);

// ---------------------------------------------------------------- shapes

// Owns every Bullet shape (and mesh storage) the oracle creates.
struct ShapeStore {
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btTriangleMesh>> meshes;
  template <class T, class... Args>
  T* make(Args&&... args) {
    auto p = std::make_unique<T>(std::forward<Args>(args)...);
    T* raw = p.get();
    shapes.push_back(std::move(p));
    return raw;
  }
};

// The collision margin of boxes and cylinders (bullet_shapes.cpp):
//   Thin          a quarter of the smallest half size for any shape thinner
//                 than 0.16 m, so the rounding stays small beside the shape
//   BulletDefault Bullet's 0.04 m, as a program that never sets it gets;
//                 only below 0.04 m of half size, where Bullet's core would
//                 turn inside out, the quarter rule (with a note)
enum class MarginRule { Thin, BulletDefault };

// The Bullet shape of `s` in its own frame (s.local is applied by the
// caller). `who` names the body for notes ("body 'crate' shapes[1]").
btCollisionShape* makeShape(const ShapeDesc& s, ShapeStore& store, std::vector<std::string>& notes,
                            const std::string& who, MarginRule margins = MarginRule::Thin);

// Radius of a sphere that fits inside the shape (for Bullet's swept-sphere
// CCD); 0 for planes and meshes.
Real innerRadius(const ShapeDesc& s);

// ------------------------------------------------------- row softness (CFM)
//
// Bullet's joint rows iterate  dl = (rhs - J v)/A - cfm_b l  (no CFM in the
// diagonal A = J M^-1 J^T), so their fixed point is J v = rhs - A cfm_b l.
// cairn's rows (ODE's convention) reach J v = rhs - (CFM / h) l. The same
// fixed point needs cfm_b = CFM / (h A) per row, which depends on the row's
// effective mass: CairnCfm<> below recomputes it from the row's Jacobian each
// time Bullet builds the row. A frequency softness is already relative to
// the effective mass: cfm_b = 1 / (h w (h w + 2 zeta)) with no A at all.
struct RowCfm {
  Real ode = 0;       // ODE CFM (velocity per unit force); contributes ode / (h A)
  Real relative = 0;  // Bullet's own, multiplies A
};

struct RowSoftness {
  Real erp = 0;
  RowCfm cfm;
};

// cairn's resolution order (constraints/softness.hpp): the axis softness if
// set, else the joint's, else the solver's global ERP and CFM.
RowSoftness resolveRowSoftness(const Softness* axis, const Softness& joint, Real global_erp, Real global_cfm, Real h);

// Spring: a 6-dof-2 spring row, whose CFM Bullet sets itself (0).
enum class RowRole { Joint, Limit, Motor, Spring };

struct CfmPlan {
  RowCfm joint, limit, motor;
  std::function<RowRole(int row)> role;  // empty: every row is a joint row
  bool active = true;                    // false: leave Bullet's own CFM alone
  bool clamped = false;                  // a row needed cfm_b > 0.5, which Bullet's PGS cannot converge
};

// Overwrites info->cfm of the constraint's `rows` rows from the plan.
void applyCfmPlan(const btTypedConstraint& c, btTypedConstraint::btConstraintInfo2* info, int rows, CfmPlan& plan);

// A Bullet constraint whose rows get the plan's CFM after Bullet filled them.
template <class Base>
class CairnCfm final : public Base {
 public:
  template <class... Args>
  explicit CairnCfm(Args&&... args) : Base(std::forward<Args>(args)...) {}
  CfmPlan plan;

  void getInfo1(btTypedConstraint::btConstraintInfo1* info) override {
    Base::getInfo1(info);
    rows_ = info->m_numConstraintRows;
  }
  void getInfo2(btTypedConstraint::btConstraintInfo2* info) override {
    Base::getInfo2(info);
    applyCfmPlan(*this, info, rows_, plan);
  }

 private:
  int rows_ = 0;
};

// ------------------------------------------------------------------ joints

// What the oracle keeps of a joint to measure its anchor separation.
enum class JointMeasure { Point, OffAxis, Distance, None };

struct JointEnd {
  btRigidBody* body = nullptr;  // btTypedConstraint::getFixedBody() for the world
  bool dynamic = false;
};

struct BuiltJoint {
  std::unique_ptr<btTypedConstraint> constraint;  // null when Bullet cannot build it
  CfmPlan* plan = nullptr;                        // inside `constraint` when it uses cairn's CFM
  JointMeasure measure = JointMeasure::Point;
  Vec3 local_a = Vec3::Zero(), local_b = Vec3::Zero();  // anchors in Bullet's body frames
  Vec3 local_axis_a = Vec3::UnitX();                    // slider axis in a's Bullet frame
  Real length = 0;                                      // distance joint
};

struct JointContext {
  const SolverSettings* solver = nullptr;
  Real h = Real(1) / 60;  // Bullet's internal step (dt / substeps)
  bool match = true;
  std::vector<std::string>* notes = nullptr;
};

BuiltJoint buildJoint(const JointDef& def, const JointEnd& a, const JointEnd& b, const JointContext& ctx);

// Axis limits, springs and motors of a six_dof joint on a 6-dof-2 built with
// Bullet's A = cairn's b, B = cairn's a and both frames `frame` (columns x =
// axis, y = axis2, z) at `anchor` (bullet_six_dof.cpp).
void configureSixDof(CairnCfm<btGeneric6DofSpring2Constraint>& c, const JointDef& def, const Vec3& anchor,
                     const Mat3& frame, const SolverSettings& s, Real h, bool match, std::vector<std::string>& notes,
                     const std::string& who);

}  // namespace cairn::validation::detail
