#include "constraints/contact.hpp"

#include <cmath>

namespace cairn {

namespace {

ConstraintRow makeRow(const BodyView& a, const BodyView& b, const Vec3& lin, const Vec3& ra, const Vec3& rb, Real cfm,
                      RowKind kind, std::int32_t owner, int slot) {
  ConstraintRow r;
  r.body_a = a.solver_index;
  r.body_b = b.solver_index;
  r.j_lin_a = -lin;
  r.j_ang_a = -ra.cross(lin);
  r.j_lin_b = lin;
  r.j_ang_b = rb.cross(lin);
  r.m_lin_a = a.inv_mass * a.lin_factor.cwiseProduct(r.j_lin_a);
  r.m_ang_a = a.inv_inertia * r.j_ang_a;
  r.m_lin_b = b.inv_mass * b.lin_factor.cwiseProduct(r.j_lin_b);
  r.m_ang_b = b.inv_inertia * r.j_ang_b;
  const Real diag = r.j_lin_a.dot(r.m_lin_a) + r.j_ang_a.dot(r.m_ang_a) + r.j_lin_b.dot(r.m_lin_b) +
                    r.j_ang_b.dot(r.m_ang_b);
  r.cfm = cfm;
  r.inv_diag = diag + cfm > 0 ? 1 / (diag + cfm) : 0;
  r.kind = kind;
  r.owner = owner;
  r.owner_row = static_cast<std::int8_t>(slot);
  return r;
}

ConstraintRow makeAngularRow(const BodyView& a, const BodyView& b, const Vec3& u, Real cfm, std::int32_t owner, int slot) {
  ConstraintRow r = makeRow(a, b, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), cfm, RowKind::ContactRolling, owner, slot);
  r.j_ang_a = -u;
  r.j_ang_b = u;
  r.m_ang_a = a.inv_inertia * r.j_ang_a;
  r.m_ang_b = b.inv_inertia * r.j_ang_b;
  const Real diag = r.j_ang_a.dot(r.m_ang_a) + r.j_ang_b.dot(r.m_ang_b);
  r.inv_diag = diag + cfm > 0 ? 1 / (diag + cfm) : 0;
  return r;
}

}  // namespace

void buildContactNormalRows(Contact& c, std::int32_t owner, const BodyView& a, const BodyView& b,
                            const ContactRowSettings& s, std::vector<ConstraintRow>& rows) {
  const Vec3& n = c.normal;
  const Real cfm = s.cfm / s.h;
  const Real warm = s.warm_start ? s.warm_start_factor : Real(0);
  for (int i = 0; i < c.count; ++i) {
    ContactPointState& p = c.points[i];
    const Vec3 pa = worldPoint(a, p.local_a), pb = worldPoint(b, p.local_b);
    const Vec3 ra = pa - a.x, rb = pb - b.x;
    const Real sep = (pb - pa).dot(n);
    p.normal_row = p.friction_row = -1;

    ConstraintRow nr = makeRow(a, b, n, ra, rb, cfm, RowKind::ContactNormal, owner, i);
    if (nr.inv_diag == 0) continue;
    nr.lo = 0;
    nr.hi = kInf;
    const bool bounce = c.restitution > 0 && -p.approach_speed > s.restitution_threshold;
    // Push-out speed for the penetration beyond the slop (zero when within).
    const Real push = sep > 0 ? 0 : std::clamp(s.contact_erp / s.h * (-sep - s.slop), Real(0), s.max_correction_velocity);
    if (sep > 0) {
      // Speculative: the gap may close this step but no more -- unless the
      // bodies meet within the step, when Newton's law applies at once.
      nr.rhs = -sep / s.h;
      if (bounce && sep + s.h * p.approach_speed < 0) nr.rhs = -c.restitution * p.approach_speed;
    } else {
      nr.rhs = bounce ? -c.restitution * p.approach_speed : 0;
    }
    if (s.correction == Correction::InRhs) {
      nr.rhs = std::max(nr.rhs, push);
    } else {
      // Every normal row of the manifold takes part in the correction pass
      // (target 0 within the slop, -gap/h while separated), so pushing one
      // corner out lifts the body instead of tipping it.
      nr.correction = s.correction;
      nr.bias_rhs = sep > 0 ? -sep / s.h : push;
    }
    nr.lambda = warm * p.normal_impulse;
    p.normal_row = static_cast<std::int32_t>(rows.size());
    rows.push_back(nr);
  }
}

void buildContactFrictionRows(Contact& c, std::int32_t owner, const BodyView& a, const BodyView& b,
                              const ContactRowSettings& s, std::int32_t island_begin, std::vector<ConstraintRow>& rows) {
  const Vec3& n = c.normal;
  const Real cfm = s.cfm / s.h;
  const Real warm = s.warm_start ? s.warm_start_factor : Real(0);
  int deepest = 0;
  for (int i = 0; i < c.count; ++i)
    if (c.points[i].depth > c.points[deepest].depth) deepest = i;
  if (c.friction > 0) {  // only what the scene needs: no friction rows for mu = 0
    for (int i = 0; i < c.count; ++i) {
      ContactPointState& p = c.points[i];
      if (p.normal_row < 0) continue;
      const Vec3 ra = worldPoint(a, p.local_a) - a.x;
      const Vec3 rb = worldPoint(b, p.local_b) - b.x;
      // Tangents: along the sliding direction when sliding, so the pyramid
      // does not favour axes; otherwise along the carried friction impulse,
      // else any perpendicular.
      const Vec3 vrel = (b.v + b.w.cross(rb)) - (a.v + a.w.cross(ra));
      const Vec3 vt = vrel - n * n.dot(vrel);
      const Vec3 carried = p.friction_impulse - n * n.dot(p.friction_impulse);
      Vec3 t1;
      if (vt.norm() > Real(1e-3)) t1 = vt.normalized();
      else if (carried.norm() > Real(1e-12)) t1 = carried.normalized();
      else t1 = anyPerpendicular(n);
      const Vec3 t2 = n.cross(t1);
      p.friction_row = static_cast<std::int32_t>(rows.size());
      for (int k = 0; k < s.friction_directions; ++k) {
        const Vec3 t = k == 0 ? t1 : t2;
        ConstraintRow fr = makeRow(a, b, t, ra, rb, cfm, RowKind::ContactFriction, owner, 4 + 2 * i + k);
        fr.normal_row = p.normal_row - island_begin;
        fr.mu = c.friction;
        fr.lambda = warm * p.friction_impulse.dot(t);
        rows.push_back(fr);
      }
    }
  }

  c.rolling_row = -1;
  const bool rolling = c.rolling_friction > 0, torsion = c.torsional_friction > 0;
  if ((rolling || torsion) && c.count > 0 && c.points[deepest].normal_row >= 0) {
    c.rolling_row = static_cast<std::int32_t>(rows.size());
    const Vec3 t1 = anyPerpendicular(n), t2 = n.cross(t1);
    const Vec3 axes[3] = {n, t1, t2};
    for (int k = 0; k < 3; ++k) {
      const Real coeff = k == 0 ? c.torsional_friction : c.rolling_friction;
      if (coeff <= 0) continue;
      ConstraintRow rr = makeAngularRow(a, b, axes[k], cfm, owner, 12 + k);
      if (rr.inv_diag == 0) continue;
      rr.normal_row = c.points[deepest].normal_row - island_begin;
      rr.mu = coeff * c.count;
      rr.lambda = warm * c.rolling_impulse.dot(axes[k]);
      rows.push_back(rr);
    }
  }
}

void storeContactImpulses(Contact& c, const std::vector<ConstraintRow>& rows) {
  for (int i = 0; i < c.count; ++i) {
    ContactPointState& p = c.points[i];
    if (p.normal_row < 0) continue;
    p.normal_impulse = rows[static_cast<size_t>(p.normal_row)].lambda;
    p.friction_impulse.setZero();
    if (p.friction_row >= 0) {
      for (size_t r = static_cast<size_t>(p.friction_row); r < rows.size() && r < static_cast<size_t>(p.friction_row) + 2; ++r) {
        const ConstraintRow& fr = rows[r];
        if (fr.kind != RowKind::ContactFriction || fr.owner_row < 4 + 2 * i || fr.owner_row > 5 + 2 * i) break;
        p.friction_impulse += fr.j_lin_b * fr.lambda;
      }
    }
  }
  c.rolling_impulse.setZero();
  if (c.rolling_row >= 0) {
    for (size_t r = static_cast<size_t>(c.rolling_row); r < rows.size(); ++r) {
      const ConstraintRow& rr = rows[r];
      if (rr.kind != RowKind::ContactRolling || rr.owner != rows[static_cast<size_t>(c.rolling_row)].owner) break;
      c.rolling_impulse += rr.j_ang_b * rr.lambda;
    }
  }
}

}  // namespace cairn
