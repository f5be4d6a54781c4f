// The contact solver's inner loops, written once for any vector width W
// (1, 4 or 8 doubles) with GCC/Clang vector extensions. Included only by
// contact_kernels_portable.cpp, contact_kernels_avx2.cpp and
// contact_kernels_avx512.cpp, each inside its own namespace
// (CAIRN_KERNEL_NS) and compiled with its own target flags.
//
// Nothing here may call a function shared with other translation units
// (no Eigen, no std:: templates): an inline function compiled with AVX-512
// in one unit and picked by the linker for another would break the
// portable path on older CPUs. Only builtins and this file's own static
// functions are used.
//
// Per lane the arithmetic is fixed and independent of W: masks freeze a
// lane's iteration when it is done instead of letting its neighbours decide,
// so W = 1, 4 and 8 give the same bits.
//
// Equations (contact_batch.hpp has the layout): for a point i with anchors
// r_a, r_b, normal n and J v = n . dv, dv = (v_b + w_b x r_b) - (v_a + w_a x r_a):
//
//   normal block    A_b d = (rhs - J v) - cfm lambda, projected on lambda + d >= 0
//                   (Cholesky factor L of A_b when every point pushes, else
//                   projected Gauss-Seidel sweeps on A_b: pgs.hpp)
//   friction        per point, t then n x t, each a row:
//                   l' = clamp(l + sor (-(t . dv) - cfm l) / (A_tt + cfm),
//                              -mu lambda_n, mu lambda_n)
//   impulse P at r  v_a -= m_a^-1 P, w_a -= I_a^-1 (r_a x P); b gets +.
#pragma once

#include "solver/contact_kernels.hpp"

#include <cstdint>

namespace cairn {
namespace CAIRN_KERNEL_NS {
namespace {

template <int W> struct VecTypes;
template <> struct VecTypes<1> {
  typedef double D __attribute__((vector_size(8)));
  typedef long long M __attribute__((vector_size(8)));
};
template <> struct VecTypes<4> {
  typedef double D __attribute__((vector_size(32)));
  typedef long long M __attribute__((vector_size(32)));
};
template <> struct VecTypes<8> {
  typedef double D __attribute__((vector_size(64)));
  typedef long long M __attribute__((vector_size(64)));
};

template <int W>
struct Kernel {
  using D = typename VecTypes<W>::D;
  using M = typename VecTypes<W>::M;

  struct V3 {
    D x, y, z;
  };
  // Symmetric 3x3: xx, yy, zz, xy, xz, yz.
  struct S3 {
    D xx, yy, zz, xy, xz, yz;
  };

  static inline __attribute__((always_inline)) D ld(const double* p) {
    D r = {};
    __builtin_memcpy(&r, p, sizeof r);
    return r;
  }
  static inline __attribute__((always_inline)) void st(double* p, D v) { __builtin_memcpy(p, &v, sizeof v); }
  static inline __attribute__((always_inline)) D splat(double x) {
    D r = {};
    return r + x;
  }
  static inline __attribute__((always_inline)) D vmax(D a, D b) { return a > b ? a : b; }
  static inline __attribute__((always_inline)) D vabs(D a) { return a < 0 ? -a : a; }
  static inline __attribute__((always_inline)) D sel(M m, D a, D b) { return m ? a : b; }
  static inline bool any(M m) {
    for (int i = 0; i < W; ++i)
      if (m[i]) return true;
    return false;
  }
  static inline bool all(M m) {
    for (int i = 0; i < W; ++i)
      if (!m[i]) return false;
    return true;
  }
  static inline double hmax(D a) {
    double r = a[0];
    for (int i = 1; i < W; ++i) r = a[i] > r ? a[i] : r;
    return r;
  }

  static inline __attribute__((always_inline)) V3 ld3(const double (*p)[kBatchLanes], int o) {
    return V3{ld(p[0] + o), ld(p[1] + o), ld(p[2] + o)};
  }
  static inline __attribute__((always_inline)) void st3(double (*p)[kBatchLanes], int o, const V3& v) {
    st(p[0] + o, v.x);
    st(p[1] + o, v.y);
    st(p[2] + o, v.z);
  }
  static inline __attribute__((always_inline)) S3 lds(const double (*p)[kBatchLanes], int o) {
    return S3{ld(p[0] + o), ld(p[1] + o), ld(p[2] + o), ld(p[3] + o), ld(p[4] + o), ld(p[5] + o)};
  }
  static inline __attribute__((always_inline)) V3 add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  static inline __attribute__((always_inline)) V3 sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static inline __attribute__((always_inline)) V3 mul(const V3& a, D s) { return {a.x * s, a.y * s, a.z * s}; }
  static inline __attribute__((always_inline)) V3 cmul(const V3& a, const V3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
  static inline __attribute__((always_inline)) D dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
  static inline __attribute__((always_inline)) V3 cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  static inline __attribute__((always_inline)) V3 mulS(const S3& m, const V3& v) {
    return {m.xx * v.x + m.xy * v.y + m.xz * v.z, m.xy * v.x + m.yy * v.y + m.yz * v.z,
            m.xz * v.x + m.yz * v.y + m.zz * v.z};
  }

  // The two bodies of W lanes.
  struct Pair {
    V3 va, wa, vb, wb;
  };

  static inline void gather(const double* bodies, const std::int32_t* ia, const std::int32_t* ib, Pair& s) {
    s = Pair{};
    for (int i = 0; i < W; ++i) {
      const double* a = bodies + 8 * static_cast<long>(ia[i]);
      const double* b = bodies + 8 * static_cast<long>(ib[i]);
      s.va.x[i] = a[0];
      s.va.y[i] = a[1];
      s.va.z[i] = a[2];
      s.wa.x[i] = a[3];
      s.wa.y[i] = a[4];
      s.wa.z[i] = a[5];
      s.vb.x[i] = b[0];
      s.vb.y[i] = b[1];
      s.vb.z[i] = b[2];
      s.wb.x[i] = b[3];
      s.wb.y[i] = b[4];
      s.wb.z[i] = b[5];
    }
  }

  // Writes back only dynamic bodies: static and kinematic ones are read
  // only, so nothing (not even a NaN) reaches another island through them.
  static inline void scatter(double* bodies, const std::int32_t* ia, const std::int32_t* ib, const Pair& s,
                             int dynamic_end, M active) {
    for (int i = 0; i < W; ++i) {
      if (!active[i]) continue;
      if (ia[i] > 0 && ia[i] < dynamic_end) {
        double* a = bodies + 8 * static_cast<long>(ia[i]);
        a[0] = s.va.x[i];
        a[1] = s.va.y[i];
        a[2] = s.va.z[i];
        a[3] = s.wa.x[i];
        a[4] = s.wa.y[i];
        a[5] = s.wa.z[i];
      }
      if (ib[i] > 0 && ib[i] < dynamic_end) {
        double* b = bodies + 8 * static_cast<long>(ib[i]);
        b[0] = s.vb.x[i];
        b[1] = s.vb.y[i];
        b[2] = s.vb.z[i];
        b[3] = s.wb.x[i];
        b[4] = s.wb.y[i];
        b[5] = s.wb.z[i];
      }
    }
  }

  // Lanes whose island still sweeps (all, without island_active).
  static inline M activeLanes(const ContactBatch& b, int o, const double* island_active) {
    D a = splat(1);
    if (island_active)
      for (int i = 0; i < W; ++i) a[i] = island_active[b.island[o + i]];
    return a > 0;
  }
  static inline M allLanes() {
    const D one = splat(1);
    return one > 0;
  }

  static inline bool lanesEmpty(const ContactBatch& b, int o) {
    for (int i = 0; i < W; ++i)
      if (b.count[o + i] > 0) return false;
    return true;
  }
  static inline bool pointEmpty(const ContactBatch& b, int o, int point) {
    for (int i = 0; i < W; ++i)
      if (b.count[o + i] > point) return false;
    return true;
  }

  // Relative velocity of the point: (v_b + w_b x r_b) - (v_a + w_a x r_a).
  static inline __attribute__((always_inline)) V3 relVel(const Pair& s, const V3& ra, const V3& rb) {
    return sub(add(s.vb, cross(s.wb, rb)), add(s.va, cross(s.wa, ra)));
  }

  // Applies impulse P at (ra, rb): a gets -P, b gets +P.
  static inline __attribute__((always_inline)) void applyAt(Pair& s, const V3& ma, const S3& ia, const V3& mb,
                                                            const S3& ib, const V3& ra, const V3& rb, const V3& p) {
    s.va = sub(s.va, cmul(ma, p));
    s.wa = sub(s.wa, mulS(ia, cross(ra, p)));
    s.vb = add(s.vb, cmul(mb, p));
    s.wb = add(s.wb, mulS(ib, cross(rb, p)));
  }

  static inline int tri(int i, int j) { return i * (i + 1) / 2 + j; }  // i >= j

  // The block solve of one manifold's normal rows toward targets `res`
  // (velocity errors, target - J v) from impulses `lam`; returns the
  // changes `dd` and leaves lam + dd in `lam`. `valid` masks real points.
  static inline void solveBlock(const ContactBatch& b, int o, const D* res, D* lam, const D* valid, D cfm, D sor,
                                const D* inv_diag, D* dd) {
    D scale = splat(0);
    for (int i = 0; i < kMaxPoints; ++i) scale = vmax(scale, vabs(res[i]));
    const D tol = scale * 1e-6;

    D l[10], a[10];
    for (int k = 0; k < 10; ++k) {
      l[k] = ld(b.factor[k] + o);
      a[k] = ld(b.block[k] + o);
    }
    // Every point pushing: forward and back substitution with L.
    D y[4], d[4];
    for (int i = 0; i < 4; ++i) {
      D sum = res[i] - cfm * lam[i];
      for (int k = 0; k < i; ++k) sum -= l[tri(i, k)] * y[k];
      y[i] = sum / l[tri(i, i)];
    }
    M accept = lam[0] == lam[0];  // all true
    for (int i = 3; i >= 0; --i) {
      D sum = y[i];
      for (int k = i + 1; k < 4; ++k) sum -= l[tri(k, i)] * d[k];
      d[i] = sum / l[tri(i, i)];
      accept &= (lam[i] + d[i] >= 0);
    }
    // The velocity errors left with the true A_b (the factor carries a
    // 1e-12 regularisation for singular face blocks).
    for (int i = 0; i < 4; ++i) {
      D w = res[i] - cfm * (lam[i] + d[i]);
      for (int k = 0; k < 4; ++k) w -= a[i >= k ? tri(i, k) : tri(k, i)] * d[k];
      accept &= (vabs(w) <= tol);
    }
    for (int i = 0; i < 4; ++i) {
      const D next = vmax(lam[i] + sor * d[i], splat(0));
      dd[i] = sel(accept, next - lam[i], splat(0));
    }
    if (!all(accept)) {
      // Projected sweeps on A_b for the lanes whose points do not all push,
      // each lane until its own velocity errors are below tol (at most 32).
      D fd[4] = {splat(0), splat(0), splat(0), splat(0)};
      D fl[4] = {lam[0], lam[1], lam[2], lam[3]};
      M done = accept;
      for (int sweep = 0; sweep < 32; ++sweep) {
        D worst = splat(0);
        for (int i = 0; i < 4; ++i) {
          D jv = splat(0);
          for (int k = 0; k < 4; ++k) jv += a[i >= k ? tri(i, k) : tri(k, i)] * fd[k];
          const D w = (res[i] - jv - cfm * fl[i]) * valid[i];
          const M counts = (w > 0) | (fl[i] > 0);
          worst = vmax(worst, sel(counts, vabs(w), splat(0)));
          const D next = vmax(fl[i] + sor * w * inv_diag[i], splat(0));
          fd[i] = sel(done, fd[i], fd[i] + (next - fl[i]));
          fl[i] = sel(done, fl[i], next);
        }
        done |= (worst <= tol);
        if (all(done)) break;
      }
      for (int i = 0; i < 4; ++i) dd[i] = sel(accept, dd[i], fd[i]);
    }
    for (int i = 0; i < 4; ++i) lam[i] += dd[i];
  }

  static void warmStart(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p) {
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        Pair s;
        gather(bodies, b.body_a + o, b.body_b + o, s);
        const V3 n = ld3(b.n, o), ma = ld3(b.ma, o), mb = ld3(b.mb, o);
        const S3 ia = lds(b.ia, o), ib = lds(b.ib, o);
        for (int i = 0; i < kMaxPoints; ++i) {
          if (pointEmpty(b, o, i)) break;
          const ContactBatch::Point& q = b.p[i];
          const V3 t1 = ld3(q.t, o), t2 = cross(n, t1);
          const V3 imp = add(mul(n, ld(q.lambda + o)), add(mul(t1, ld(q.lambda_t[0] + o)), mul(t2, ld(q.lambda_t[1] + o))));
          applyAt(s, ma, ia, mb, ib, ld3(q.ra, o), ld3(q.rb, o), imp);
        }
        scatter(bodies, b.body_a + o, b.body_b + o, s, p.dynamic_end, allLanes());
      }
    }
  }

  static void solve(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p) {
    const D sor = splat(p.sor);
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        const M active = activeLanes(b, o, p.island_active);
        if (!any(active)) continue;
        D maxd = splat(0), maxl = splat(0);
        Pair s;
        gather(bodies, b.body_a + o, b.body_b + o, s);
        const V3 n = ld3(b.n, o), ma = ld3(b.ma, o), mb = ld3(b.mb, o);
        const S3 ia = lds(b.ia, o), ib = lds(b.ib, o);
        const D cfm = ld(b.cfm + o);

        // Normal block.
        D res[4], lam[4], valid[4], inv_diag[4], dd[4];
        for (int i = 0; i < 4; ++i) {
          const ContactBatch::Point& q = b.p[i];
          valid[i] = ld(q.valid + o);
          lam[i] = ld(q.lambda + o);
          inv_diag[i] = ld(q.normal_mass + o);
          const V3 dv = relVel(s, ld3(q.ra, o), ld3(q.rb, o));
          res[i] = (ld(q.rhs + o) - dot(n, dv)) * valid[i];
        }
        solveBlock(b, o, res, lam, valid, cfm, sor, inv_diag, dd);
        D sum = splat(0);
        V3 ta{splat(0), splat(0), splat(0)}, tb = ta;
        D ch2 = splat(0);
        for (int i = 0; i < 4; ++i) {
          ContactBatch::Point& q = b.p[i];
          dd[i] = sel(active, dd[i], splat(0));
          lam[i] = sel(active, lam[i], ld(q.lambda + o));
          sum += dd[i];
          ta = add(ta, mul(ld3(q.ra, o), dd[i]));
          tb = add(tb, mul(ld3(q.rb, o), dd[i]));
          st(q.lambda + o, lam[i]);
          st(q.max_lambda + o, vmax(ld(q.max_lambda + o), lam[i]));
          maxd = vmax(maxd, vabs(dd[i]));
          maxl = vmax(maxl, lam[i]);
          if (p.gather_change) {
            st(q.change_n + o, dd[i]);
            ch2 += dd[i] * dd[i];
          }
        }
        // Sum of the point impulses n dd_i: one update per body.
        const V3 pn = mul(n, sum);
        s.va = sub(s.va, cmul(ma, pn));
        s.vb = add(s.vb, cmul(mb, pn));
        s.wa = sub(s.wa, mulS(ia, cross(ta, n)));
        s.wb = add(s.wb, mulS(ib, cross(tb, n)));

        // Friction per point: two tangent rows, t then n x t, each bounded by
        // mu lambda_n of its point (the friction pyramid, as ODE and Bullet
        // with two directions; t is along the sliding direction when
        // sliding, so the pyramid's corners do not bias a sliding body).
        const D mu = ld(b.mu + o);
        if (any(mu > 0)) {
          for (int i = 0; i < kMaxPoints; ++i) {
            if (pointEmpty(b, o, i)) break;
            ContactBatch::Point& q = b.p[i];
            const V3 ra = ld3(q.ra, o), rb = ld3(q.rb, o);
            const V3 t1 = ld3(q.t, o);
            const D limit = mu * lam[i];
            for (int k = 0; k < 2; ++k) {
              const V3 t = k == 0 ? t1 : cross(n, t1);
              const D l = ld(q.lambda_t[k] + o);
              const D jv = dot(t, relVel(s, ra, rb));
              D next = l + sor * (-jv - cfm * l) * ld(q.tangent_mass[k] + o);
              next = vmax(next, -limit);
              next = next < limit ? next : limit;
              next = sel(active, next, l);
              const D d = next - l;
              applyAt(s, ma, ia, mb, ib, ra, rb, mul(t, d));
              st(q.lambda_t[k] + o, next);
              maxd = vmax(maxd, vabs(d));
              maxl = vmax(maxl, vabs(next));
              if (p.gather_change) {
                st(q.change_t[k] + o, d);
                ch2 += d * d;
              }
            }
          }
        }
        if (p.gather_change) st(b.change2 + o, ch2);
        st(b.sweep_delta + o, maxd);
        st(b.sweep_lambda + o, maxl);
        scatter(bodies, b.body_a + o, b.body_b + o, s, p.dynamic_end, active);
      }
    }
  }

  static void momentum(ContactBatch* batches, int begin, int end, double* bodies, const double* island_beta,
                       const ContactSweepParams& p) {
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        D beta = {};
        for (int i = 0; i < W; ++i) beta[i] = island_beta[b.island[o + i]];
        const M apply = (beta > 0) & (beta <= 1);
        const M reset_to_change = beta == 0;
        const M stopped = beta < 0;
        const V3 n = ld3(b.n, o);
        if (!any(apply)) {
          // No step anywhere in these lanes: p = change (first sweep) or 0 (restart).
          for (int i = 0; i < kMaxPoints; ++i) {
            ContactBatch::Point& q = b.p[i];
            const D zero = splat(0);
            st(q.dir_n + o, sel(stopped, ld(q.dir_n + o), sel(reset_to_change, ld(q.change_n + o), zero)));
            st(q.dir_t[0] + o, sel(stopped, ld(q.dir_t[0] + o), sel(reset_to_change, ld(q.change_t[0] + o), zero)));
            st(q.dir_t[1] + o, sel(stopped, ld(q.dir_t[1] + o), sel(reset_to_change, ld(q.change_t[1] + o), zero)));
          }
          continue;
        }
        Pair s;
        gather(bodies, b.body_a + o, b.body_b + o, s);
        const V3 ma = ld3(b.ma, o), mb = ld3(b.mb, o);
        const S3 ia = lds(b.ia, o), ib = lds(b.ib, o);
        const D mu = ld(b.mu + o);
        const D bstep = sel(apply, beta, splat(0));
        D lam[4];
        for (int i = 0; i < kMaxPoints; ++i) {
          ContactBatch::Point& q = b.p[i];
          const D l = ld(q.lambda + o), dir = ld(q.dir_n + o), ch = ld(q.change_n + o);
          const D next = sel(apply, vmax(l + bstep * dir, splat(0)), l);
          const D d = next - l;
          lam[i] = next;
          st(q.lambda + o, next);
          st(q.max_lambda + o, vmax(ld(q.max_lambda + o), next));
          st(q.dir_n + o, sel(apply, beta * dir + ch, sel(stopped, dir, sel(reset_to_change, ch, splat(0)))));
          applyAt(s, ma, ia, mb, ib, ld3(q.ra, o), ld3(q.rb, o), mul(n, d));
        }
        for (int i = 0; i < kMaxPoints; ++i) {
          ContactBatch::Point& q = b.p[i];
          const V3 ra = ld3(q.ra, o), rb = ld3(q.rb, o), t1 = ld3(q.t, o);
          const D limit = mu * lam[i];
          for (int k = 0; k < 2; ++k) {
            const D l = ld(q.lambda_t[k] + o), dir = ld(q.dir_t[k] + o), ch = ld(q.change_t[k] + o);
            D next = vmax(l + bstep * dir, -limit);
            next = next < limit ? next : limit;
            next = sel(apply, next, l);
            st(q.lambda_t[k] + o, next);
            st(q.dir_t[k] + o, sel(apply, beta * dir + ch, sel(stopped, dir, sel(reset_to_change, ch, splat(0)))));
            applyAt(s, ma, ia, mb, ib, ra, rb, mul(k == 0 ? t1 : cross(n, t1), next - l));
          }
        }
        scatter(bodies, b.body_a + o, b.body_b + o, s, p.dynamic_end, apply);
      }
    }
  }

  static void solveBias(ContactBatch* batches, int begin, int end, double* pseudo, const ContactSweepParams& p) {
    const D sor = splat(p.sor);
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        const M active = activeLanes(b, o, p.island_active);
        if (!any(active)) continue;
        D maxd = splat(0), maxl = splat(0);
        Pair s;
        gather(pseudo, b.body_a + o, b.body_b + o, s);
        const V3 n = ld3(b.n, o), ma = ld3(b.ma, o), mb = ld3(b.mb, o);
        const S3 ia = lds(b.ia, o), ib = lds(b.ib, o);
        const D cfm = ld(b.cfm + o);
        D res[4], lam[4], valid[4], inv_diag[4], dd[4];
        for (int i = 0; i < 4; ++i) {
          const ContactBatch::Point& q = b.p[i];
          valid[i] = ld(q.valid + o);
          lam[i] = ld(q.lambda_bias + o);
          inv_diag[i] = ld(q.normal_mass + o);
          const V3 dv = relVel(s, ld3(q.ra, o), ld3(q.rb, o));
          res[i] = (ld(q.bias + o) - dot(n, dv)) * valid[i];
        }
        solveBlock(b, o, res, lam, valid, cfm, sor, inv_diag, dd);
        D sum = splat(0);
        V3 ta{splat(0), splat(0), splat(0)}, tb = ta;
        for (int i = 0; i < 4; ++i) {
          ContactBatch::Point& q = b.p[i];
          dd[i] = sel(active, dd[i], splat(0));
          lam[i] = sel(active, lam[i], ld(q.lambda_bias + o));
          sum += dd[i];
          ta = add(ta, mul(ld3(q.ra, o), dd[i]));
          tb = add(tb, mul(ld3(q.rb, o), dd[i]));
          st(q.lambda_bias + o, lam[i]);
          maxd = vmax(maxd, vabs(dd[i]));
          maxl = vmax(maxl, lam[i]);
        }
        const V3 pn = mul(n, sum);
        s.va = sub(s.va, cmul(ma, pn));
        s.vb = add(s.vb, cmul(mb, pn));
        s.wa = sub(s.wa, mulS(ia, cross(ta, n)));
        s.wb = add(s.wb, mulS(ib, cross(tb, n)));
        st(b.sweep_delta + o, maxd);
        st(b.sweep_lambda + o, maxl);
        scatter(pseudo, b.body_a + o, b.body_b + o, s, p.dynamic_end, active);
      }
    }
  }

  static void restitution(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p) {
    const D sor = splat(p.sor);
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        // Points that bounce: a bounce target, and a normal impulse during the step.
        D bouncing[4];
        M lane_bounces = splat(0) != splat(0);  // all false
        for (int i = 0; i < 4; ++i) {
          const ContactBatch::Point& q = b.p[i];
          const M m = (ld(q.bounce + o) != 0) & (ld(q.max_lambda + o) > 0) & (ld(q.valid + o) > 0);
          bouncing[i] = sel(m, splat(1), splat(0));
          lane_bounces |= m;
        }
        if (!any(lane_bounces)) continue;
        Pair s;
        gather(bodies, b.body_a + o, b.body_b + o, s);
        const V3 n = ld3(b.n, o), ma = ld3(b.ma, o), mb = ld3(b.mb, o);
        const S3 ia = lds(b.ia, o), ib = lds(b.ib, o);
        const D cfm = ld(b.cfm + o);
        D res[4], lam[4], inv_diag[4], a[10];
        for (int k = 0; k < 10; ++k) a[k] = ld(b.block[k] + o);
        D scale = splat(0);
        for (int i = 0; i < 4; ++i) {
          const ContactBatch::Point& q = b.p[i];
          lam[i] = ld(q.lambda + o);
          inv_diag[i] = ld(q.normal_mass + o);
          const V3 dv = relVel(s, ld3(q.ra, o), ld3(q.rb, o));
          res[i] = (ld(q.bounce + o) - dot(n, dv)) * bouncing[i];
          scale = vmax(scale, vabs(res[i]));
        }
        // Projected sweeps on the bouncing points' block, each lane until
        // its velocity errors fall below 1e-6 of the largest it began with.
        const D tol = scale * 1e-6;
        D fd[4] = {splat(0), splat(0), splat(0), splat(0)};
        M done = lane_bounces == 0;
        for (int sweep = 0; sweep < 32; ++sweep) {
          D worst = splat(0);
          for (int i = 0; i < 4; ++i) {
            D jv = splat(0);
            for (int k = 0; k < 4; ++k) jv += a[i >= k ? tri(i, k) : tri(k, i)] * fd[k];
            const D w = (res[i] - jv - cfm * lam[i]) * bouncing[i];
            const M counts = (w > 0) | (lam[i] > 0);
            worst = vmax(worst, sel(counts, vabs(w), splat(0)));
            const D next = vmax(lam[i] + sor * w * inv_diag[i], splat(0));
            fd[i] = sel(done, fd[i], fd[i] + (next - lam[i]));
            lam[i] = sel(done, lam[i], next);
          }
          done |= (worst <= tol);
          if (all(done)) break;
        }
        D sum = splat(0);
        V3 ta{splat(0), splat(0), splat(0)}, tb = ta;
        for (int i = 0; i < 4; ++i) {
          ContactBatch::Point& q = b.p[i];
          sum += fd[i];
          ta = add(ta, mul(ld3(q.ra, o), fd[i]));
          tb = add(tb, mul(ld3(q.rb, o), fd[i]));
          st(q.lambda + o, lam[i]);
        }
        const V3 pn = mul(n, sum);
        s.va = sub(s.va, cmul(ma, pn));
        s.vb = add(s.vb, cmul(mb, pn));
        s.wa = sub(s.wa, mulS(ia, cross(ta, n)));
        s.wb = add(s.wb, mulS(ib, cross(tb, n)));
        scatter(bodies, b.body_a + o, b.body_b + o, s, p.dynamic_end, lane_bounces);
      }
    }
  }
};

}  // namespace

// The table of this unit's kernels.
inline ContactKernels makeKernels(const char* name) {
  using K = Kernel<CAIRN_KERNEL_LANES>;
  return ContactKernels{name, CAIRN_KERNEL_LANES, &K::warmStart, &K::solve, &K::momentum, &K::solveBias, &K::restitution};
}

}  // namespace CAIRN_KERNEL_NS
}  // namespace cairn
