// Softness: ODE's ERP/CFM and the spring-damper they stand for.
//
// The ODE manual's mapping, for a row with spring constant k and damping c
// integrated implicitly over a step h (section 12.2.3's spring-damper):
//
//     ERP = h k / (h k + c),      CFM = 1 / (h k + c)
//
// and its inverse  k = ERP / (h CFM),  c = (1 - ERP) / CFM.
// For a body of mass m on the row: omega = sqrt(k / m), f = omega / (2 pi),
// damping ratio zeta = c / (2 sqrt(k m)). A frequency/damping-ratio pair is
// turned into k and c with the row's effective mass m = 1 / (J M^-1 J^T):
// k = m omega^2, c = 2 zeta m omega.
//
// CFM here is ODE's (it multiplies a force). The solver works in impulses,
// so the row's diagonal gains CFM / h (constraints/row.hpp).
#pragma once

#include "cairn/math.hpp"
#include "cairn/defs.hpp"

namespace cairn {

struct ErpCfm {
  Real erp = 0;
  Real cfm = 0;  // ODE units: velocity per unit force
};

struct SpringEquivalent {
  Real stiffness = 0;      // N/m (or N m/rad)
  Real damping = 0;        // N s/m
  Real frequency = 0;      // Hz, for the given mass
  Real damping_ratio = 0;  // for the given mass
};

ErpCfm erpCfmFromSpring(Real stiffness, Real damping, Real h);
ErpCfm erpCfmFromFrequency(Real frequency_hz, Real damping_ratio, Real mass, Real h);
SpringEquivalent springFromErpCfm(Real erp, Real cfm, Real h, Real mass);

// The ERP and CFM a row uses: the most specific softness that is set
// (axis, then joint), else the solver's global values. `effective_mass` is
// needed only for the frequency spelling.
ErpCfm resolveSoftness(const Softness* axis, const Softness& joint, Real global_erp, Real global_cfm,
                       Real effective_mass, Real h);

// Validates a softness spelling (throws InputError naming object/field).
void validateSoftness(const Softness& s, const std::string& object, const std::string& prefix);

}  // namespace cairn
