#include "constraints/softness.hpp"

#include "cairn/error.hpp"

#include <cmath>

namespace cairn {

ErpCfm erpCfmFromSpring(Real k, Real c, Real h) {
  const Real denom = h * k + c;
  if (denom <= 0) return {0, kInf};  // no spring, no damper: the row does nothing
  return {h * k / denom, 1 / denom};
}

ErpCfm erpCfmFromFrequency(Real f, Real zeta, Real mass, Real h) {
  const Real omega = 2 * kPi * f;
  return erpCfmFromSpring(mass * omega * omega, 2 * zeta * mass * omega, h);
}

SpringEquivalent springFromErpCfm(Real erp, Real cfm, Real h, Real mass) {
  SpringEquivalent s;
  if (cfm <= 0) {  // rigid: infinite stiffness
    s.stiffness = s.damping = s.frequency = kInf;
    s.damping_ratio = erp < 1 ? kInf : 0;
    return s;
  }
  s.stiffness = erp / (h * cfm);
  s.damping = (1 - erp) / cfm;
  s.frequency = std::sqrt(s.stiffness / mass) / (2 * kPi);
  s.damping_ratio = s.stiffness > 0 ? s.damping / (2 * std::sqrt(s.stiffness * mass)) : kInf;
  return s;
}

namespace {

bool resolveOne(const Softness& s, Real global_erp, Real global_cfm, Real m, Real h, ErpCfm& out) {
  if (s.stiffness || s.damping) {
    out = erpCfmFromSpring(s.stiffness.value_or(0), s.damping.value_or(0), h);
    return true;
  }
  if (s.frequency) {
    out = erpCfmFromFrequency(*s.frequency, s.damping_ratio.value_or(1), m, h);
    return true;
  }
  if (s.erp || s.cfm) {
    out = {s.erp.value_or(global_erp), s.cfm.value_or(global_cfm)};
    return true;
  }
  return false;
}

}  // namespace

ErpCfm resolveSoftness(const Softness* axis, const Softness& joint, Real global_erp, Real global_cfm,
                       Real m, Real h) {
  ErpCfm out{global_erp, global_cfm};
  if (axis && resolveOne(*axis, global_erp, global_cfm, m, h, out)) return out;
  resolveOne(joint, global_erp, global_cfm, m, h, out);
  return out;
}

void validateSoftness(const Softness& s, const std::string& obj, const std::string& p) {
  const auto nonneg = [&](const std::optional<Real>& v, const char* f) {
    if (v && (!std::isfinite(*v) || *v < 0))
      throw InputError(obj, p + f, "must be finite and >= 0 (got " + std::to_string(*v) + ")");
  };
  if (s.erp && (!std::isfinite(*s.erp) || *s.erp < 0 || *s.erp > 1))
    throw InputError(obj, p + "erp", "must lie in [0, 1] (got " + std::to_string(*s.erp) + ")");
  if (s.cfm && (!std::isfinite(*s.cfm) || *s.cfm < 0))
    throw InputError(obj, p + "cfm", "must be finite and >= 0 (got " + std::to_string(*s.cfm) + ")");
  nonneg(s.stiffness, "stiffness");
  nonneg(s.damping, "damping");
  nonneg(s.damping_ratio, "damping_ratio");
  if (s.frequency && (!std::isfinite(*s.frequency) || *s.frequency <= 0))
    throw InputError(obj, p + "frequency", "must be positive and finite");
  const int spellings = (s.erp || s.cfm) + (s.stiffness || s.damping) + (s.frequency || s.damping_ratio);
  if (spellings > 1)
    throw InputError(obj, p + "erp", "give one softness spelling: erp/cfm, stiffness/damping or frequency/damping_ratio");
  if (s.damping_ratio && !s.frequency) throw InputError(obj, p + "damping_ratio", "needs a frequency");
}

}  // namespace cairn
