// The contact solver's inner loops, written once for any vector width W
// (2, 4 or 8 doubles) with GCC/Clang vector extensions. Included only by
// contact_kernels_portable.cpp, contact_kernels_avx2.cpp and
// contact_kernels_avx512.cpp, each inside its own namespace
// (CAIRN_KERNEL_NS) and compiled with its own target flags.
//
// Nothing here may call a function shared with other translation units
// (no Eigen, no std:: templates): an inline function compiled with AVX-512
// in one unit and picked by the linker for another would break the
// portable path on older CPUs. Only builtins, the compiler's intrinsics
// (internal linkage) and this file's own static functions are used.
//
// Per lane the arithmetic is fixed and independent of W: masks freeze a
// lane's iteration when it is done instead of letting its neighbours decide,
// so W = 2, 4 and 8 give the same bits.
//
// Equations (contact_batch.hpp has the layout): a row along u at a point
// with angular Jacobians -(r_a x u) and r_b x u has
//   J v = u . (v_b - v_a) + (r_b x u) . w_b - (r_a x u) . w_a
// and an impulse d along it changes
//   v_a -= m_a^-1 u d,  w_a -= I_a^-1 (r_a x u) d,  v_b += m_b^-1 u d,  w_b += I_b^-1 (r_b x u) d.
//
//   normal block    A_b d = (rhs - J v) - cfm lambda, projected on lambda + d >= 0
//                   (Cholesky factor L of A_b when every point pushes, else
//                   projected Gauss-Seidel sweeps on A_b: pgs.hpp); the
//                   points' impulses, all along n, reach the bodies in one
//                   update: v_a -= m_a^-1 n sum d_i, w_a -= I_a^-1 sum d_i (r_a x n)_i
//   friction        per point, t then n x t, each a row:
//                   l' = clamp(l + sor (-J v - cfm l) / (A_tt + cfm),
//                              -mu lambda_n, mu lambda_n)
//   patch friction  per manifold (contact_batch.hpp): the tangent pair at
//                   the centre as a 2 x 2 block K (+ cfm),
//                   l' = proj_disc(l - sor K^-1 (J v + cfm l), mu sum lambda_n),
//                   then the twist row, J v = n . (w_b - w_a),
//                   clamped to +-mu sum lambda_n,i d_i
#pragma once

#include "solver/contact_kernels.hpp"

#include <cstdint>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

namespace cairn {
namespace CAIRN_KERNEL_NS {
namespace {

template <int W> struct VecTypes;
// No VecTypes<1>: GCC 12 at -O2 folds a one-element mask wrongly once a
// branch has tested it (after `if (!any(run)) continue;`, `run & (beta ==
// 0)` came out zero for beta == 0), so the portable kernels use two lanes.
template <> struct VecTypes<2> {
  typedef double D __attribute__((vector_size(16)));
  typedef long long M __attribute__((vector_size(16)));
};
template <> struct VecTypes<4> {
  typedef double D __attribute__((vector_size(32)));
  typedef long long M __attribute__((vector_size(32)));
};
template <> struct VecTypes<8> {
  typedef double D __attribute__((vector_size(64)));
  typedef long long M __attribute__((vector_size(64)));
};

#define CAIRN_INLINE static inline __attribute__((always_inline))

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

  CAIRN_INLINE D ld(const double* p) {
    D r;
    __builtin_memcpy(&r, p, sizeof r);
    return r;
  }
  CAIRN_INLINE void st(double* p, D v) { __builtin_memcpy(p, &v, sizeof v); }
  CAIRN_INLINE D splat(double x) {
    D r = {};
    return r + x;
  }
  CAIRN_INLINE D zero() { return D{}; }
  CAIRN_INLINE D vmax(D a, D b) { return a > b ? a : b; }
  CAIRN_INLINE D vmin(D a, D b) { return a < b ? a : b; }
  CAIRN_INLINE D vabs(D a) { return a < 0 ? -a : a; }
  CAIRN_INLINE D sel(M m, D a, D b) { return m ? a : b; }
  CAIRN_INLINE D vsqrt(D a) {
#if defined(__AVX512F__)
    if constexpr (W == 8) {
      __m512d r;
      __builtin_memcpy(&r, &a, 64);
      r = _mm512_maskz_sqrt_pd(0xFF, r);  // all eight lanes (the unmasked form trips GCC 12's -Wuninitialized)
      __builtin_memcpy(&a, &r, 64);
      return a;
    }
#endif
#if defined(__AVX__)
    if constexpr (W == 4) {
      __m256d r;
      __builtin_memcpy(&r, &a, 32);
      r = _mm256_sqrt_pd(r);
      __builtin_memcpy(&a, &r, 32);
      return a;
    }
#endif
    for (int i = 0; i < W; ++i) a[i] = __builtin_sqrt(a[i]);  // IEEE: correctly rounded, as the vector forms
    return a;
  }
  CAIRN_INLINE M allTrue() {
    const D one = splat(1);
    return one > 0;
  }
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

  CAIRN_INLINE V3 ld3(const double (*p)[kBatchLanes], int o) { return V3{ld(p[0] + o), ld(p[1] + o), ld(p[2] + o)}; }
  CAIRN_INLINE S3 lds(const double (*p)[kBatchLanes], int o) {
    return S3{ld(p[0] + o), ld(p[1] + o), ld(p[2] + o), ld(p[3] + o), ld(p[4] + o), ld(p[5] + o)};
  }
  CAIRN_INLINE V3 add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  CAIRN_INLINE V3 sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  CAIRN_INLINE V3 mul(const V3& a, D s) { return {a.x * s, a.y * s, a.z * s}; }
  CAIRN_INLINE V3 cmul(const V3& a, const V3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
  CAIRN_INLINE D dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
  CAIRN_INLINE V3 cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  CAIRN_INLINE V3 mulS(const S3& m, const V3& v) {
    return {m.xx * v.x + m.xy * v.y + m.xz * v.z, m.xy * v.x + m.yy * v.y + m.yz * v.z,
            m.xz * v.x + m.yz * v.y + m.zz * v.z};
  }
  CAIRN_INLINE V3 zero3() { return V3{zero(), zero(), zero()}; }

  // The two bodies of W lanes: their velocities, and their mass data.
  struct Pair {
    V3 va, wa, vb, wb;
  };
  struct Mass {
    V3 ma, mb;
    S3 ia, ib;
  };
  CAIRN_INLINE Mass loadMass(const ContactBatch& b, int o) {
    return Mass{ld3(b.ma, o), ld3(b.mb, o), lds(b.ia, o), lds(b.ib, o)};
  }

  // --- Gathering and scattering the bodies' velocities. A body is 8
  // doubles (v, w, two spare); for W bodies the kernel needs the six
  // velocity components as six vectors: a transpose. The scatter writes a
  // body back as whole vectors too, the transpose run the other way (it is
  // its own inverse) with zeros for the spare pair, which is never anything
  // else (solver/solver_body.hpp). The next visit to read the body (the
  // friction visit after the normal one, the next colour's) loads it as
  // whole vectors: from six scalar stores the processor cannot forward
  // such a load, which then waits for the stores to reach the cache;
  // from stores of the load's own size and place it can
  // (docs/performance.md, "Now: bodies written back as whole lines").
#if defined(__AVX512F__)
  // 8 x 8 transpose of doubles in three stages of two-lane, four-lane and
  // 128-bit shuffles: out[k] holds element k of in[0..7].
  static inline __attribute__((always_inline)) void transpose8(const __m512d* in, __m512d* out) {
    const __m512d t0 = _mm512_unpacklo_pd(in[0], in[1]), t1 = _mm512_unpackhi_pd(in[0], in[1]);
    const __m512d t2 = _mm512_unpacklo_pd(in[2], in[3]), t3 = _mm512_unpackhi_pd(in[2], in[3]);
    const __m512d t4 = _mm512_unpacklo_pd(in[4], in[5]), t5 = _mm512_unpackhi_pd(in[4], in[5]);
    const __m512d t6 = _mm512_unpacklo_pd(in[6], in[7]), t7 = _mm512_unpackhi_pd(in[6], in[7]);
    const __m512i lo = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0), hi = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
    const __m512d u0 = _mm512_permutex2var_pd(t0, lo, t2), u1 = _mm512_permutex2var_pd(t1, lo, t3);
    const __m512d u2 = _mm512_permutex2var_pd(t0, hi, t2), u3 = _mm512_permutex2var_pd(t1, hi, t3);
    const __m512d u4 = _mm512_permutex2var_pd(t4, lo, t6), u5 = _mm512_permutex2var_pd(t5, lo, t7);
    const __m512d u6 = _mm512_permutex2var_pd(t4, hi, t6), u7 = _mm512_permutex2var_pd(t5, hi, t7);
    const __m512i a = _mm512_set_epi64(11, 10, 9, 8, 3, 2, 1, 0), c = _mm512_set_epi64(15, 14, 13, 12, 7, 6, 5, 4);
    out[0] = _mm512_permutex2var_pd(u0, a, u4);
    out[1] = _mm512_permutex2var_pd(u1, a, u5);
    out[2] = _mm512_permutex2var_pd(u2, a, u6);
    out[3] = _mm512_permutex2var_pd(u3, a, u7);
    out[4] = _mm512_permutex2var_pd(u0, c, u4);
    out[5] = _mm512_permutex2var_pd(u1, c, u5);
    out[6] = _mm512_permutex2var_pd(u2, c, u6);
    out[7] = _mm512_permutex2var_pd(u3, c, u7);
  }
#endif
#if defined(__AVX2__)
  // 4 x 4 transpose of doubles: out[k] holds element k of in[0..3].
  static inline __attribute__((always_inline)) void transpose4(const __m256d* in, __m256d* out) {
    const __m256d a0 = _mm256_unpacklo_pd(in[0], in[1]), a1 = _mm256_unpackhi_pd(in[0], in[1]);
    const __m256d a2 = _mm256_unpacklo_pd(in[2], in[3]), a3 = _mm256_unpackhi_pd(in[2], in[3]);
    out[0] = _mm256_permute2f128_pd(a0, a2, 0x20);
    out[1] = _mm256_permute2f128_pd(a1, a3, 0x20);
    out[2] = _mm256_permute2f128_pd(a0, a2, 0x31);
    out[3] = _mm256_permute2f128_pd(a1, a3, 0x31);
  }
#endif
  // The six velocity components of W bodies between (v, w) and six
  // registers of W doubles (R: the instruction set's vector of W doubles;
  // a V3 is three of them, unpadded).
  template <class R>
  static inline __attribute__((always_inline)) void toVelocities(const R* c, V3& v, V3& w) {
    static_assert(sizeof(V3) == 3 * sizeof(R));
    __builtin_memcpy(&v, c, sizeof v);
    __builtin_memcpy(&w, c + 3, sizeof w);
  }
  template <class R>
  static inline __attribute__((always_inline)) void fromVelocities(const V3& v, const V3& w, R* c) {
    static_assert(sizeof(V3) == 3 * sizeof(R));
    __builtin_memcpy(c, &v, sizeof v);
    __builtin_memcpy(c + 3, &w, sizeof w);
  }

  CAIRN_INLINE void gather1(const double* bodies, const std::int32_t* idx, V3& v, V3& w) {
#if defined(__AVX512F__)
    if constexpr (W == 8) {
      __m512d r[8], c[8];
      for (int i = 0; i < 8; ++i) r[i] = _mm512_loadu_pd(bodies + 8 * static_cast<long>(idx[i]));
      transpose8(r, c);  // c[k]: component k of the eight bodies
      toVelocities(c, v, w);
      return;
    }
#endif
#if defined(__AVX2__)
    if constexpr (W == 4) {
      __m256d lo[4], hi[4], c[8];
      for (int i = 0; i < 4; ++i) {
        const double* p = bodies + 8 * static_cast<long>(idx[i]);
        lo[i] = _mm256_loadu_pd(p);      // vx vy vz wx
        hi[i] = _mm256_loadu_pd(p + 4);  // wy wz s s
      }
      transpose4(lo, c);
      transpose4(hi, c + 4);
      toVelocities(c, v, w);
      return;
    }
#endif
    for (int i = 0; i < W; ++i) {
      const double* p = bodies + 8 * static_cast<long>(idx[i]);
      v.x[i] = p[0];
      v.y[i] = p[1];
      v.z[i] = p[2];
      w.x[i] = p[3];
      w.y[i] = p[4];
      w.z[i] = p[5];
    }
  }

  CAIRN_INLINE void gather(const double* bodies, const ContactBatch& b, int o, Pair& s) {
    gather1(bodies, b.body_a + o, s.va, s.wa);
    gather1(bodies, b.body_b + o, s.vb, s.wb);
  }

  // Writes back only dynamic bodies of the lanes in `write`: static and
  // kinematic ones are read only, so nothing (not even a NaN) reaches
  // another island through them. Lanes are written in order, as a body
  // twice in one vector (never in a colour's batch) would be by scalars.
  static inline bool writes(const std::int32_t* idx, int i, int dynamic_end, M write) {
    return write[i] && idx[i] > 0 && idx[i] < dynamic_end;
  }
  CAIRN_INLINE void scatter1(double* bodies, const std::int32_t* idx, const V3& v, const V3& w, int dynamic_end,
                             M write) {
#if defined(__AVX512F__)
    if constexpr (W == 8) {
      __m512d c[8], r[8];
      fromVelocities(v, w, c);
      c[6] = c[7] = _mm512_setzero_pd();  // the spare pair
      transpose8(c, r);  // r[i]: body i's line
      for (int i = 0; i < 8; ++i)
        if (writes(idx, i, dynamic_end, write)) _mm512_storeu_pd(bodies + 8 * static_cast<long>(idx[i]), r[i]);
      return;
    }
#endif
#if defined(__AVX2__)
    if constexpr (W == 4) {
      __m256d c[8], lo[4], hi[4];
      fromVelocities(v, w, c);
      c[6] = c[7] = _mm256_setzero_pd();
      transpose4(c, lo);      // vx vy vz wx of each body
      transpose4(c + 4, hi);  // wy wz and the spare pair
      for (int i = 0; i < 4; ++i) {
        if (!writes(idx, i, dynamic_end, write)) continue;
        double* p = bodies + 8 * static_cast<long>(idx[i]);
        _mm256_storeu_pd(p, lo[i]);
        _mm256_storeu_pd(p + 4, hi[i]);
      }
      return;
    }
#endif
    for (int i = 0; i < W; ++i) {
      if (!writes(idx, i, dynamic_end, write)) continue;
      double* p = bodies + 8 * static_cast<long>(idx[i]);
      p[0] = v.x[i];
      p[1] = v.y[i];
      p[2] = v.z[i];
      p[3] = w.x[i];
      p[4] = w.y[i];
      p[5] = w.z[i];
    }
  }

  CAIRN_INLINE void scatter(double* bodies, const ContactBatch& b, int o, const Pair& s, int dynamic_end, M write) {
    scatter1(bodies, b.body_a + o, s.va, s.wa, dynamic_end, write);
    scatter1(bodies, b.body_b + o, s.vb, s.wb, dynamic_end, write);
  }

  // Lanes whose island still sweeps (all, without island_active).
  static inline M activeLanes(const ContactBatch& b, int o, const double* island_active) {
    D a = splat(1);
    if (island_active)
      for (int i = 0; i < W; ++i) a[i] = island_active[b.island[o + i]];
    return a > 0;
  }
  static inline bool lanesEmpty(const ContactBatch& b, int o) {
    for (int i = 0; i < W; ++i)
      if (b.count[o + i] > 0) return false;
    return true;
  }
  static inline int maxPoints(const ContactBatch& b, int o) {
    int n = 0;
    for (int i = 0; i < W; ++i) n = b.count[o + i] > n ? b.count[o + i] : n;
    return n;
  }

  // J v of a row with linear direction u and angular parts (ra_u, rb_u).
  CAIRN_INLINE D rowVel(const Pair& s, const V3& u, const V3& ra_u, const V3& rb_u) {
    return dot(u, sub(s.vb, s.va)) + dot(rb_u, s.wb) - dot(ra_u, s.wa);
  }

  // An impulse along a row: linear part u d, angular parts (ra_u d, rb_u d).
  CAIRN_INLINE void applyRow(Pair& s, const Mass& m, const V3& u, const V3& ra_u, const V3& rb_u, D d) {
    const V3 p = mul(u, d);
    s.va = sub(s.va, cmul(m.ma, p));
    s.vb = add(s.vb, cmul(m.mb, p));
    s.wa = sub(s.wa, mulS(m.ia, mul(ra_u, d)));
    s.wb = add(s.wb, mulS(m.ib, mul(rb_u, d)));
  }

  // Accumulated impulses of several rows, applied at once: linear sum P
  // and angular sums (Ta, Tb), each the sum of d times the row's parts.
  struct Sum {
    V3 p, ta, tb;
  };
  CAIRN_INLINE void addRow(Sum& sum, const V3& u, const V3& ra_u, const V3& rb_u, D d) {
    sum.p = add(sum.p, mul(u, d));
    sum.ta = add(sum.ta, mul(ra_u, d));
    sum.tb = add(sum.tb, mul(rb_u, d));
  }
  CAIRN_INLINE void applySum(Pair& s, const Mass& m, const Sum& sum) {
    s.va = sub(s.va, cmul(m.ma, sum.p));
    s.vb = add(s.vb, cmul(m.mb, sum.p));
    s.wa = sub(s.wa, mulS(m.ia, sum.ta));
    s.wb = add(s.wb, mulS(m.ib, sum.tb));
  }

  // Patch friction: the pair (l0, l1) scaled back onto the disc of radius
  // `limit` when outside it (the Coulomb cone; limit >= 0).
  CAIRN_INLINE void clampDisc(D& l0, D& l1, D limit) {
    const D mag2 = l0 * l0 + l1 * l1;
    const M over = mag2 > limit * limit;
    const D scale = sel(over, limit / vsqrt(sel(over, mag2, splat(1))), splat(1));
    l0 = l0 * scale;
    l1 = l1 * scale;
  }
  // A patch's tangent pair, in point 0's tangent fields: t1, t2 = n x t1
  // and their angular parts at the centre's anchors.
  struct PairRows {
    V3 t1, t2, ra1, rb1, ra2, rb2;
  };
  CAIRN_INLINE PairRows pairRows(const ContactBatch::Point& q, int o, const V3& n) {
    const V3 t1 = ld3(q.t, o), t2 = cross(n, t1), ra = ld3(q.ra, o), rb = ld3(q.rb, o);
    return {t1, t2, cross(ra, t1), cross(rb, t1), cross(ra, t2), cross(rb, t2)};
  }
  // The patch's bounds from its points' normal impulses: mu sum lambda_i
  // for the tangent pair, mu sum lambda_i d_i for the twist.
  CAIRN_INLINE void patchLimits(const ContactBatch& b, int o, int points, D mu, const D* lam, D& limit, D& twist_limit) {
    D total = zero(), load = zero();
    for (int i = 0; i < points; ++i) {
      total += lam[i];
      load += lam[i] * ld(b.arm[i] + o);
    }
    limit = mu * total;
    twist_limit = mu * load;
  }

  // Projected sweeps on a block whose points do not all push. Two, not the
  // scalar solver's 32 (pgs.cpp): the block solve is one visit of an outer
  // Gauss-Seidel sweep that comes back to it anyway, and in a vector of
  // lanes one lane still sweeping holds all of them. Measured (`cairn bench
  // pyramid-20 --cairn-set sleeping=true`): 32 sweeps 0.40 ms/step, drift
  // 1.51 cm, penetration 1.55 mm; 2 sweeps 0.26 ms/step, 1.35 cm, 1.31 mm
  // (the pyramid settles and sleeps sooner); 1, 4 and 8 lie between. The
  // extremes table holds the same cases (docs/performance.md).
  static constexpr int kBlockSweeps = 2;
  static constexpr int tri(int i, int j) { return i * (i + 1) / 2 + j; }  // i >= j
  static constexpr int sym(int i, int k) { return i >= k ? tri(i, k) : tri(k, i); }

  // The block solve of one manifold's normal rows toward targets `res`
  // (velocity errors, target - J v) from impulses `lam`; returns the
  // changes `dd` and leaves lam + dd in `lam`. `valid` masks real points.
  CAIRN_INLINE void solveBlock(const ContactBatch& b, int o, const D* res, D* lam, const D* valid, D cfm, D sor,
                                const D* inv_diag, D* dd) {
    D scale = zero();
    for (int i = 0; i < kMaxPoints; ++i) scale = vmax(scale, vabs(res[i]));
    const D tol = scale * 1e-6;

    // Every point pushing: forward and back substitution with L.
    D y[4], d[4];
    for (int i = 0; i < 4; ++i) {
      D sum = res[i] - cfm * lam[i];
      for (int k = 0; k < i; ++k) sum -= ld(b.factor[tri(i, k)] + o) * y[k];
      y[i] = sum / ld(b.factor[tri(i, i)] + o);
    }
    M accept = allTrue();
    for (int i = 3; i >= 0; --i) {
      D sum = y[i];
      for (int k = i + 1; k < 4; ++k) sum -= ld(b.factor[tri(k, i)] + o) * d[k];
      d[i] = sum / ld(b.factor[tri(i, i)] + o);
      accept &= (lam[i] + d[i] >= 0);
    }
    // The velocity errors left with the true A_b (the factor carries a
    // 1e-12 regularisation for singular face blocks).
    D a[10];
    for (int k = 0; k < 10; ++k) a[k] = ld(b.block[k] + o);
    for (int i = 0; i < 4; ++i) {
      D w = res[i] - cfm * (lam[i] + d[i]);
      for (int k = 0; k < 4; ++k) w -= a[sym(i, k)] * d[k];
      accept &= (vabs(w) <= tol);
    }
    for (int i = 0; i < 4; ++i) {
      const D next = vmax(lam[i] + sor * d[i], zero());
      dd[i] = sel(accept, next - lam[i], zero());
    }
    if (!all(accept)) {
      // Projected sweeps on A_b for the lanes whose points do not all push,
      // each lane until its own velocity errors are below tol (at most kBlockSweeps).
      D fd[4] = {zero(), zero(), zero(), zero()};
      D fl[4] = {lam[0], lam[1], lam[2], lam[3]};
      M done = accept;
      for (int sweep = 0; sweep < kBlockSweeps; ++sweep) {
        D worst = zero();
        for (int i = 0; i < 4; ++i) {
          D jv = zero();
          for (int k = 0; k < 4; ++k) jv += a[sym(i, k)] * fd[k];
          const D w = (res[i] - jv - cfm * fl[i]) * valid[i];
          const M counts = (w > 0) | (fl[i] > 0);
          worst = vmax(worst, sel(counts, vabs(w), zero()));
          const D next = vmax(fl[i] + sor * w * inv_diag[i], zero());
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
        gather(bodies, b, o, s);
        const Mass m = loadMass(b, o);
        const V3 n = ld3(b.n, o);
        Sum sum{zero3(), zero3(), zero3()};
        const int points = maxPoints(b, o);
        for (int i = 0; i < points; ++i) {
          const ContactBatch::Point& q = b.p[i];
          addRow(sum, n, ld3(q.ran, o), ld3(q.rbn, o), ld(q.lambda + o));
          if (p.patch && i > 0) continue;  // the patch's rows are point 0's
          const V3 t1 = ld3(q.t, o), ra = ld3(q.ra, o), rb = ld3(q.rb, o);
          // The tangent rows in use (a row past friction_rows holds zeros: it would add nothing).
          addRow(sum, t1, cross(ra, t1), cross(rb, t1), ld(q.lambda_t[0] + o));
          if (p.friction_rows > 1 || p.patch) {
            const V3 t2 = cross(n, t1);
            addRow(sum, t2, cross(ra, t2), cross(rb, t2), ld(q.lambda_t[1] + o));
          }
        }
        if (p.patch) addRow(sum, zero3(), n, n, ld(b.lambda_twist + o));
        applySum(s, m, sum);
        scatter(bodies, b, o, s, p.dynamic_end, allTrue());
      }
    }
  }

  // One projected Gauss-Seidel visit of lanes [o, o + W)'s normal blocks on
  // the velocities v (the bodies' or the correction's pseudo-velocities),
  // from the impulses in `impulse` toward the targets in `target`: the
  // velocity pass and the correction pass differ only in these and in what
  // they record, which `record(point, new impulse, change)` does per point.
  // The lanes' largest change and impulse grow maxd and maxl.
  using PointLanes = ContactBatch::Lanes ContactBatch::Point::*;
  template <class Record>
  CAIRN_INLINE void blockVisit(ContactBatch& b, int o, double* v, PointLanes impulse, PointLanes target, int dynamic_end,
                               D sor, M active, D& maxd, D& maxl, Record&& record) {
    Pair s;
    gather(v, b, o, s);
    const Mass m = loadMass(b, o);
    const V3 n = ld3(b.n, o);
    const D cfm = ld(b.cfm + o);
    D res[4], lam[4], valid[4], inv_diag[4], dd[4];
    const D n_dv = dot(n, sub(s.vb, s.va));
    for (int i = 0; i < 4; ++i) {
      const ContactBatch::Point& q = b.p[i];
      valid[i] = ld(q.valid + o);
      lam[i] = ld(q.*impulse + o);
      inv_diag[i] = ld(q.normal_mass + o);
      const D jv = n_dv + dot(ld3(q.rbn, o), s.wb) - dot(ld3(q.ran, o), s.wa);
      res[i] = (ld(q.*target + o) - jv) * valid[i];
    }
    solveBlock(b, o, res, lam, valid, cfm, sor, inv_diag, dd);
    D total = zero();
    V3 ta = zero3(), tb = zero3();
    for (int i = 0; i < 4; ++i) {
      ContactBatch::Point& q = b.p[i];
      dd[i] = sel(active, dd[i], zero());
      lam[i] = sel(active, lam[i], ld(q.*impulse + o));
      total += dd[i];
      ta = add(ta, mul(ld3(q.ran, o), dd[i]));
      tb = add(tb, mul(ld3(q.rbn, o), dd[i]));
      st(q.*impulse + o, lam[i]);
      record(q, lam[i], dd[i]);
      maxd = vmax(maxd, vabs(dd[i]));
      maxl = vmax(maxl, lam[i]);
    }
    applySum(s, m, Sum{mul(n, total), ta, tb});
    scatter(v, b, o, s, dynamic_end, active);
  }

  // One projected Gauss-Seidel visit of every manifold's normal block.
  static void solveNormals(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p) {
    const D sor = splat(p.sor);
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        if (p.pseudo) {  // the correction's visit, while the lanes are in hand
          const M bias_active = activeLanes(b, o, p.pseudo_active);
          if (any(bias_active)) biasLanes(b, o, p.pseudo, p, sor, bias_active);
        }
        const M active = activeLanes(b, o, p.island_active);
        if (!any(active)) continue;
        D maxd = zero(), maxl = zero(), ch2 = zero();
        blockVisit(b, o, bodies, &ContactBatch::Point::lambda, &ContactBatch::Point::rhs, p.dynamic_end, sor, active, maxd,
                   maxl, [&](ContactBatch::Point& q, D lam, D dd) {
                     st(q.max_lambda + o, vmax(ld(q.max_lambda + o), lam));
                     if (p.gather_change) {
                       st(q.change_n + o, dd);
                       ch2 += dd * dd;
                     }
                   });
        if (p.gather_change) st(b.change2 + o, ch2);
        st(b.sweep_delta + o, maxd);
        st(b.sweep_lambda + o, maxl);
      }
    }
  }

  // One visit of lanes [o, o + W)'s friction patches (solveFriction with
  // SolverSettings::patch_friction): the tangent pair at the centre solved
  // as its 2 x 2 block from the same velocities and projected on the disc,
  // then the twist row against the velocities the pair left.
  CAIRN_INLINE void patchVisit(ContactBatch& b, int o, Pair& s, const Mass& m, const V3& n, D cfm, D mu, int points, D sor,
                               M active, bool gather, D& maxd, D& maxl, D& ch2) {
    D lam[kMaxPoints];
    for (int i = 0; i < points; ++i) lam[i] = ld(b.p[i].lambda + o);
    D limit, twist_limit;
    patchLimits(b, o, points, mu, lam, limit, twist_limit);
    ContactBatch::Point& q = b.p[0];
    const PairRows r = pairRows(q, o, n);
    const D l0 = ld(q.lambda_t[0] + o), l1 = ld(q.lambda_t[1] + o);
    const D v0 = rowVel(s, r.t1, r.ra1, r.rb1) + cfm * l0, v1 = rowVel(s, r.t2, r.ra2, r.rb2) + cfm * l1;
    const D k00 = ld(b.patch_mass[0] + o), k01 = ld(b.patch_mass[1] + o), k11 = ld(b.patch_mass[2] + o);
    D n0 = l0 - sor * (k00 * v0 + k01 * v1), n1 = l1 - sor * (k01 * v0 + k11 * v1);
    clampDisc(n0, n1, limit);
    n0 = sel(active, n0, l0);
    n1 = sel(active, n1, l1);
    const D d0 = n0 - l0, d1 = n1 - l1;
    Sum sum{zero3(), zero3(), zero3()};
    addRow(sum, r.t1, r.ra1, r.rb1, d0);
    addRow(sum, r.t2, r.ra2, r.rb2, d1);
    applySum(s, m, sum);
    st(q.lambda_t[0] + o, n0);
    st(q.lambda_t[1] + o, n1);
    const D lt = ld(b.lambda_twist + o);
    D nt = lt + sor * (-dot(n, sub(s.wb, s.wa)) - cfm * lt) * ld(b.twist_mass + o);
    nt = vmin(vmax(nt, -twist_limit), twist_limit);
    nt = sel(active, nt, lt);
    const D dt = nt - lt;
    const V3 nd = mul(n, dt);
    s.wa = sub(s.wa, mulS(m.ia, nd));
    s.wb = add(s.wb, mulS(m.ib, nd));
    st(b.lambda_twist + o, nt);
    maxd = vmax(maxd, vmax(vmax(vabs(d0), vabs(d1)), vabs(dt)));
    maxl = vmax(maxl, vmax(vmax(vabs(n0), vabs(n1)), vabs(nt)));
    if (gather) {
      st(q.change_t[0] + o, d0);
      st(q.change_t[1] + o, d1);
      st(b.change_twist + o, dt);
      ch2 += d0 * d0 + d1 * d1 + dt * dt;
    }
  }

  // One projected Gauss-Seidel visit of every manifold's friction rows,
  // after the normal pass of the same sweep: per point two tangent rows, t
  // then n x t, each bounded by mu lambda_n of its point (the friction
  // pyramid, as ODE and Bullet with two directions; t is along the sliding
  // direction when sliding, so the pyramid's corners do not bias a sliding
  // body). The lane's sweep figures grow from the normal pass's.
  static void solveFriction(ContactBatch* batches, int begin, int end, double* bodies, const ContactSweepParams& p) {
    const D sor = splat(p.sor);
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        const D mu = ld(b.mu + o);
        const M active = activeLanes(b, o, p.island_active) & (mu > 0);
        if (!any(active)) continue;
        Pair s;
        gather(bodies, b, o, s);
        const Mass m = loadMass(b, o);
        const V3 n = ld3(b.n, o);
        const D cfm = ld(b.cfm + o);
        const int points = maxPoints(b, o);
        D maxd = ld(b.sweep_delta + o), maxl = ld(b.sweep_lambda + o);
        D ch2 = p.gather_change ? ld(b.change2 + o) : zero();
        if (p.patch) {
          patchVisit(b, o, s, m, n, cfm, mu, points, sor, active, p.gather_change, maxd, maxl, ch2);
          if (p.gather_change) st(b.change2 + o, ch2);
          st(b.sweep_delta + o, maxd);
          st(b.sweep_lambda + o, maxl);
          scatter(bodies, b, o, s, p.dynamic_end, active);
          continue;
        }
        for (int i = 0; i < points; ++i) {
          ContactBatch::Point& q = b.p[i];
          const V3 t1 = ld3(q.t, o), ra = ld3(q.ra, o), rb = ld3(q.rb, o);
          const D limit = mu * ld(q.lambda + o);
          for (int k = 0; k < p.friction_rows; ++k) {
            const V3 u = k == 0 ? t1 : cross(n, t1);
            const V3 ra_u = cross(ra, u), rb_u = cross(rb, u);
            const D l = ld(q.lambda_t[k] + o);
            D next = l + sor * (-rowVel(s, u, ra_u, rb_u) - cfm * l) * ld(q.tangent_mass[k] + o);
            next = vmin(vmax(next, -limit), limit);
            next = sel(active, next, l);
            const D d = next - l;
            applyRow(s, m, u, ra_u, rb_u, d);
            st(q.lambda_t[k] + o, next);
            maxd = vmax(maxd, vabs(d));
            maxl = vmax(maxl, vabs(next));
            if (p.gather_change) {
              st(q.change_t[k] + o, d);
              ch2 += d * d;
            }
          }
        }
        if (p.gather_change) st(b.change2 + o, ch2);
        st(b.sweep_delta + o, maxd);
        st(b.sweep_lambda + o, maxl);
        scatter(bodies, b, o, s, p.dynamic_end, active);
      }
    }
  }

  // NNCG's momentum step of lanes [o, o + W) with patch friction: the
  // normal impulses as per point, then the patch's pair projected on the
  // disc and its twist on the bounds of the new normal impulses.
  template <class NewDir>
  CAIRN_INLINE void patchMomentum(ContactBatch& b, int o, const V3& n, D mu, int points, M apply, D bstep, NewDir&& newDir,
                                  Sum& sum) {
    D lam[kMaxPoints];
    for (int i = 0; i < points; ++i) {
      ContactBatch::Point& q = b.p[i];
      const D l = ld(q.lambda + o), dir = ld(q.dir_n + o);
      lam[i] = sel(apply, vmax(l + bstep * dir, zero()), l);
      st(q.lambda + o, lam[i]);
      st(q.max_lambda + o, vmax(ld(q.max_lambda + o), lam[i]));
      st(q.dir_n + o, newDir(dir, ld(q.change_n + o)));
      addRow(sum, n, ld3(q.ran, o), ld3(q.rbn, o), lam[i] - l);
    }
    D limit, twist_limit;
    patchLimits(b, o, points, mu, lam, limit, twist_limit);
    ContactBatch::Point& q = b.p[0];
    const D l0 = ld(q.lambda_t[0] + o), l1 = ld(q.lambda_t[1] + o);
    const D p0 = ld(q.dir_t[0] + o), p1 = ld(q.dir_t[1] + o);
    D n0 = l0 + bstep * p0, n1 = l1 + bstep * p1;
    clampDisc(n0, n1, limit);
    n0 = sel(apply, n0, l0);
    n1 = sel(apply, n1, l1);
    st(q.lambda_t[0] + o, n0);
    st(q.lambda_t[1] + o, n1);
    st(q.dir_t[0] + o, newDir(p0, ld(q.change_t[0] + o)));
    st(q.dir_t[1] + o, newDir(p1, ld(q.change_t[1] + o)));
    const PairRows r = pairRows(q, o, n);
    addRow(sum, r.t1, r.ra1, r.rb1, n0 - l0);
    addRow(sum, r.t2, r.ra2, r.rb2, n1 - l1);
    const D lt = ld(b.lambda_twist + o), pt = ld(b.dir_twist + o);
    const D nt = sel(apply, vmin(vmax(lt + bstep * pt, -twist_limit), twist_limit), lt);
    st(b.lambda_twist + o, nt);
    st(b.dir_twist + o, newDir(pt, ld(b.change_twist + o)));
    addRow(sum, zero3(), n, n, nt - lt);
  }

  // NNCG's momentum: lambda' = proj(lambda + beta p); the changes need no
  // velocity, so they are summed and reach the bodies once per manifold.
  static void momentum(ContactBatch* batches, int begin, int end, double* bodies, const double* island_beta,
                       const ContactSweepParams& p) {
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        D beta = zero();
        for (int i = 0; i < W; ++i) beta[i] = island_beta[b.island[o + i]];
        const M apply = (beta > 0) & (beta <= 1);
        const M reset_to_change = beta == 0;
        const M stopped = beta < 0;
        const int points = maxPoints(b, o);
        const auto newDir = [&](D dir, D ch) { return sel(apply, beta * dir + ch, sel(stopped, dir, sel(reset_to_change, ch, zero()))); };
        if (!any(apply)) {
          // No step anywhere in these lanes: p = change (first sweep) or 0 (restart).
          for (int i = 0; i < points; ++i) {
            ContactBatch::Point& q = b.p[i];
            st(q.dir_n + o, newDir(ld(q.dir_n + o), ld(q.change_n + o)));
            if (p.patch && i > 0) continue;
            for (int k = 0; k < (p.patch ? 2 : p.friction_rows); ++k)
              st(q.dir_t[k] + o, newDir(ld(q.dir_t[k] + o), ld(q.change_t[k] + o)));
          }
          if (p.patch) st(b.dir_twist + o, newDir(ld(b.dir_twist + o), ld(b.change_twist + o)));
          continue;
        }
        Pair s;
        gather(bodies, b, o, s);
        const Mass m = loadMass(b, o);
        const V3 n = ld3(b.n, o);
        const D mu = ld(b.mu + o);
        const D bstep = sel(apply, beta, zero());
        Sum sum{zero3(), zero3(), zero3()};
        if (p.patch) {
          patchMomentum(b, o, n, mu, points, apply, bstep, newDir, sum);
          applySum(s, m, sum);
          scatter(bodies, b, o, s, p.dynamic_end, apply);
          continue;
        }
        for (int i = 0; i < points; ++i) {
          ContactBatch::Point& q = b.p[i];
          const D l = ld(q.lambda + o), dir = ld(q.dir_n + o);
          const D ln = sel(apply, vmax(l + bstep * dir, zero()), l);
          st(q.lambda + o, ln);
          st(q.max_lambda + o, vmax(ld(q.max_lambda + o), ln));
          st(q.dir_n + o, newDir(dir, ld(q.change_n + o)));
          addRow(sum, n, ld3(q.ran, o), ld3(q.rbn, o), ln - l);
          const V3 t1 = ld3(q.t, o), ra = ld3(q.ra, o), rb = ld3(q.rb, o);
          const D limit = mu * ln;
          for (int k = 0; k < p.friction_rows; ++k) {  // a row past them stays zero
            const D lt = ld(q.lambda_t[k] + o), dt = ld(q.dir_t[k] + o);
            const D next = sel(apply, vmin(vmax(lt + bstep * dt, -limit), limit), lt);
            st(q.lambda_t[k] + o, next);
            st(q.dir_t[k] + o, newDir(dt, ld(q.change_t[k] + o)));
            const V3 u = k == 0 ? t1 : cross(n, t1);
            addRow(sum, u, cross(ra, u), cross(rb, u), next - lt);
          }
        }
        applySum(s, m, sum);
        scatter(bodies, b, o, s, p.dynamic_end, apply);
      }
    }
  }

  // One visit of lanes [o, o + W)'s normal blocks toward the correction
  // targets, on the pseudo-velocities, from lambda_bias; the lanes' largest
  // change and impulse go to bias_delta and bias_lambda.
  CAIRN_INLINE void biasLanes(ContactBatch& b, int o, double* pseudo, const ContactSweepParams& p, D sor, M active) {
    D maxd = zero(), maxl = zero();
    blockVisit(b, o, pseudo, &ContactBatch::Point::lambda_bias, &ContactBatch::Point::bias, p.dynamic_end, sor, active,
               maxd, maxl, [](ContactBatch::Point&, D, D) {});
    st(b.bias_delta + o, maxd);
    st(b.bias_lambda + o, maxl);
  }

  static void solveBias(ContactBatch* batches, int begin, int end, double* pseudo, const ContactSweepParams& p) {
    const D sor = splat(p.sor);
    for (int bi = begin; bi < end; ++bi) {
      ContactBatch& b = batches[bi];
      for (int o = 0; o < kBatchLanes; o += W) {
        if (lanesEmpty(b, o)) continue;
        const M active = activeLanes(b, o, p.island_active);
        if (any(active)) biasLanes(b, o, pseudo, p, sor, active);
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
        M lane_bounces = zero() != zero();  // all false
        for (int i = 0; i < 4; ++i) {
          const ContactBatch::Point& q = b.p[i];
          const M m = (ld(q.bounce + o) != 0) & (ld(q.max_lambda + o) > 0) & (ld(q.valid + o) > 0);
          bouncing[i] = sel(m, splat(1), zero());
          lane_bounces |= m;
        }
        if (!any(lane_bounces)) continue;
        Pair s;
        gather(bodies, b, o, s);
        const Mass m = loadMass(b, o);
        const V3 n = ld3(b.n, o);
        const D cfm = ld(b.cfm + o);
        D res[4], lam[4], inv_diag[4], a[10];
        for (int k = 0; k < 10; ++k) a[k] = ld(b.block[k] + o);
        D scale = zero();
        const D n_dv = dot(n, sub(s.vb, s.va));
        for (int i = 0; i < 4; ++i) {
          const ContactBatch::Point& q = b.p[i];
          lam[i] = ld(q.lambda + o);
          inv_diag[i] = ld(q.normal_mass + o);
          const D jv = n_dv + dot(ld3(q.rbn, o), s.wb) - dot(ld3(q.ran, o), s.wa);
          res[i] = (ld(q.bounce + o) - jv) * bouncing[i];
          scale = vmax(scale, vabs(res[i]));
        }
        // Projected sweeps on the bouncing points' block, each lane until
        // its velocity errors fall below 1e-6 of the largest it began with.
        const D tol = scale * 1e-6;
        D fd[4] = {zero(), zero(), zero(), zero()};
        M done = ~lane_bounces;
        for (int sweep = 0; sweep < 32; ++sweep) {
          D worst = zero();
          for (int i = 0; i < 4; ++i) {
            D jv = zero();
            for (int k = 0; k < 4; ++k) jv += a[sym(i, k)] * fd[k];
            const D w = (res[i] - jv - cfm * lam[i]) * bouncing[i];
            const M counts = (w > 0) | (lam[i] > 0);
            worst = vmax(worst, sel(counts, vabs(w), zero()));
            const D next = vmax(lam[i] + sor * w * inv_diag[i], zero());
            fd[i] = sel(done, fd[i], fd[i] + (next - lam[i]));
            lam[i] = sel(done, lam[i], next);
          }
          done |= (worst <= tol);
          if (all(done)) break;
        }
        D total = zero();
        V3 ta = zero3(), tb = zero3();
        for (int i = 0; i < 4; ++i) {
          ContactBatch::Point& q = b.p[i];
          total += fd[i];
          ta = add(ta, mul(ld3(q.ran, o), fd[i]));
          tb = add(tb, mul(ld3(q.rbn, o), fd[i]));
          st(q.lambda + o, lam[i]);
        }
        applySum(s, m, Sum{mul(n, total), ta, tb});
        scatter(bodies, b, o, s, p.dynamic_end, lane_bounces);
      }
    }
  }

  // --- The fill: a batch's eight manifolds into its lanes, W at a time,
  // from the gathered ContactBatchInput. The arithmetic of each lane is
  // the scalar fill's, operation for operation (Eigen's order for the
  // quaternion rotation, dots, products and normalisation), so the lanes
  // hold the same bits as when each manifold was filled alone.

  // Eigen's q * v: uv = 2 (q_vec x v); v + w uv + q_vec x uv.
  CAIRN_INLINE V3 rotate(const ContactBatchInput::Side& s, int o, const V3& v) {
    const V3 qv{ld(s.q[0] + o), ld(s.q[1] + o), ld(s.q[2] + o)};
    const D qw = ld(s.q[3] + o);
    V3 uv = cross(qv, v);
    uv = add(uv, uv);
    return add(add(v, mul(uv, qw)), cross(qv, uv));
  }
  // Row-major 3x3 times a vector, summed as Eigen sums a fixed 3x3 times
  // 3-vector product with SSE2: the first two rows left to right (one
  // packet), the third as its redux tail, a0 + (a1 + a2).
  struct M3 {
    D m[9];
  };
  CAIRN_INLINE M3 ldm(const double (*p)[kBatchLanes], int o) {
    M3 r;
    for (int k = 0; k < 9; ++k) r.m[k] = ld(p[k] + o);
    return r;
  }
  CAIRN_INLINE V3 mulM(const M3& a, const V3& v) {
    return {a.m[0] * v.x + a.m[1] * v.y + a.m[2] * v.z, a.m[3] * v.x + a.m[4] * v.y + a.m[5] * v.z,
            a.m[6] * v.x + (a.m[7] * v.y + a.m[8] * v.z)};
  }
  CAIRN_INLINE void st3(double (*p)[kBatchLanes], int o, const V3& v) {
    st(p[0] + o, v.x);
    st(p[1] + o, v.y);
    st(p[2] + o, v.z);
  }
  // The kernels' symmetric form: xx, yy, zz, xy, xz, yz of the upper triangle.
  CAIRN_INLINE void stUpper(double (*dst)[kBatchLanes], int o, const M3& m) {
    st(dst[0] + o, m.m[0]);
    st(dst[1] + o, m.m[4]);
    st(dst[2] + o, m.m[8]);
    st(dst[3] + o, m.m[1]);
    st(dst[4] + o, m.m[2]);
    st(dst[5] + o, m.m[5]);
  }
  CAIRN_INLINE V3 sel3(M m, const V3& a, const V3& b) { return {sel(m, a.x, b.x), sel(m, a.y, b.y), sel(m, a.z, b.z)}; }

  // A point's targets from its separation along the normal: close a gap
  // within the (sub)step and no more (speculative); push the penetration
  // beyond the slop out at contact_erp / h. Zeros where `ok` is clear.
  CAIRN_INLINE void putTargets(ContactBatch::Point& q, int o, M ok, D sep, const ContactFillParams& p) {
    const D zero_ = zero(), h = splat(p.h);
    const D want = splat(p.contact_erp) / h * (-sep - splat(p.slop));
    const D clamped = sel(want < 0, zero_, sel(splat(p.max_correction) < want, splat(p.max_correction), want));
    const D push = sel(sep > 0, zero_, clamped);
    D rhs = sel(sep > 0, -sep / h, zero_);
    if (p.in_rhs) {
      rhs = sel(rhs < push, push, rhs);  // std::max's choice, NaN included
      st(q.bias + o, zero_);
    } else {
      // Every point of the manifold takes part in the correction pass
      // (target 0 within the slop, -gap/h while separated), so pushing
      // one corner out lifts the body instead of tipping it.
      st(q.bias + o, sel(ok, sel(sep > 0, -sep / h, push), zero_));  // > 0: being pushed out
    }
    st(q.rhs + o, sel(ok, rhs, zero_));
  }

  // The sweeps' per-step figures of a lane group, from zero.
  CAIRN_INLINE void clearSweepState(ContactBatch& b, int o) {
    const D zero_ = zero();
    st(b.sweep_delta + o, zero_);
    st(b.sweep_lambda + o, zero_);
    st(b.change2 + o, zero_);
    for (ContactBatch::Point& q : b.p) {
      st(q.lambda_bias + o, zero_);
      st(q.change_n + o, zero_);
      st(q.dir_n + o, zero_);
      for (int k = 0; k < 2; ++k) {
        st(q.change_t[k] + o, zero_);
        st(q.dir_t[k] + o, zero_);
      }
    }
    st(b.change_twist + o, zero_);
    st(b.dir_twist + o, zero_);
  }

  // A later substep of a batch filled at the step's first (SolverSettings::
  // prepare_contacts_each_substep false): the Jacobians, effective masses,
  // tangents and the normal block stay as the fill made them, and only what
  // the bodies' motion since changes is made again: each point's
  // separation, from its anchors fixed in the bodies at their present poses
  // (in.a and in.b: x and q; in.p: the local anchors), and its targets; the
  // carried impulses are warm-started again (times the factor, as the fill
  // takes them from the contact), and the sweeps' figures start from zero.
  // Box2D v3's b2SolveContact likewise keeps each point's anchors and masses
  // over the substeps and measures the separation anew.
  static void refresh(ContactBatch& b, const ContactBatchInput& in, const ContactFillParams& p) {
    const D zero_ = zero(), warm = splat(p.warm);
    for (int o = 0; o < kBatchLanes; o += W) {
      clearSweepState(b, o);
      const V3 n = ld3(b.n, o);
      const V3 xa = ld3(in.a.x, o), xb = ld3(in.b.x, o);
      for (int i = 0; i < kMaxPoints; ++i) {
        ContactBatch::Point& q = b.p[i];
        const ContactBatchInput::Point& ip = in.p[i];
        const M ok = ld(q.valid + o) > 0;
        const V3 pa = add(xa, rotate(in.a, o, ld3(ip.local_a, o)));
        const V3 pb = add(xb, rotate(in.b, o, ld3(ip.local_b, o)));
        putTargets(q, o, ok, dot(sub(pb, pa), n), p);
        st(q.lambda + o, sel(ok, warm * ld(q.lambda + o), zero_));
        for (int k = 0; k < 2; ++k) st(q.lambda_t[k] + o, warm * ld(q.lambda_t[k] + o));
      }
      st(b.lambda_twist + o, warm * ld(b.lambda_twist + o));
    }
  }

  // The first tangent of a point (or a patch's centre) with relative
  // velocity vrel and carried friction impulse fi: along the sliding
  // direction when sliding, so the pyramid's corners do not favour axes;
  // else along the carried friction impulse, else any perpendicular
  // (anyPerpendicular in cairn/math.hpp: n x (x or y), normalised).
  CAIRN_INLINE V3 tangent(const V3& n, const V3& vrel, const V3& fi) {
    const D zero_ = zero(), one = splat(1);
    const V3 vt = sub(vrel, mul(n, dot(n, vrel)));
    const V3 carried = sub(fi, mul(n, dot(n, fi)));
    const D vt2 = dot(vt, vt), carried2 = dot(carried, carried);
    const M use_x = vabs(n.x) < 0.57735;
    const V3 axis{sel(use_x, one, zero_), sel(use_x, zero_, one), zero_};
    const V3 perp = cross(n, axis);
    const D perp2 = dot(perp, perp);
    const D rp = vsqrt(sel(perp2 > 0, perp2, one));
    V3 t1 = sel3(perp2 > 0, V3{perp.x / rp, perp.y / rp, perp.z / rp}, perp);
    const M carried_ok = carried2 > 1e-24;
    const D rc = vsqrt(sel(carried_ok, carried2, one));
    t1 = sel3(carried_ok, V3{carried.x / rc, carried.y / rc, carried.z / rc}, t1);
    const M sliding = vt2 > 1e-6;
    const D rv = vsqrt(sel(sliding, vt2, one));
    return sel3(sliding, V3{vt.x / rv, vt.y / rv, vt.z / rv}, t1);
  }

  // A manifold's friction patch (contact_batch.hpp) from its points'
  // anchors ra_i, rb_i and carried friction impulses f_i (zeros where no
  // point): the centre c is the points' mean; the carried patch impulse
  // is sum f_i and the carried twist sum n . (d_i x f_i), d_i = r_a,i - c,
  // which is what the store's split of the patch's impulses over the
  // points (world/step_solve.cpp) gives back.
  CAIRN_INLINE void fillPatch(ContactBatch& b, int o, const ContactFillParams& p, const M* valid, const V3* ras,
                              const V3* rbs, const V3* fis, const M3& ia, const M3& ib, const V3& m_ab, const V3& n, D mu,
                              const V3& va, const V3& wa, const V3& vb, const V3& wb) {
    const D zero_ = zero(), one = splat(1), cfm = splat(p.cfm), warm = splat(p.warm);
    V3 ca = zero3(), cb = zero3(), carried = zero3();
    D count = zero_;
    for (int i = 0; i < kMaxPoints; ++i) {
      ca = add(ca, sel3(valid[i], ras[i], zero3()));
      cb = add(cb, sel3(valid[i], rbs[i], zero3()));
      carried = add(carried, fis[i]);
      count += sel(valid[i], one, zero_);
    }
    const M has = count > 0;
    const D inv_count = one / sel(has, count, one);
    ca = mul(ca, inv_count);
    cb = mul(cb, inv_count);
    const V3 vrel = sub(add(vb, cross(wb, cb)), add(va, cross(wa, ca)));
    const V3 t1 = tangent(n, vrel, carried), t2 = cross(n, t1);
    const V3 ra1 = cross(ca, t1), rb1 = cross(cb, t1), ra2 = cross(ca, t2), rb2 = cross(cb, t2);
    const D k00 = dot(t1, cmul(m_ab, t1)) + dot(ra1, mulM(ia, ra1)) + dot(rb1, mulM(ib, rb1)) + cfm;
    const D k11 = dot(t2, cmul(m_ab, t2)) + dot(ra2, mulM(ia, ra2)) + dot(rb2, mulM(ib, rb2)) + cfm;
    const D k01 = dot(t1, cmul(m_ab, t2)) + dot(ra1, mulM(ia, ra2)) + dot(rb1, mulM(ib, rb2));
    const D det = k00 * k11 - k01 * k01;
    const M rubs = has & (mu > 0) & (k00 > 0) & (det > 0);
    const D inv_det = one / sel(rubs, det, one);
    ContactBatch::Point& q = b.p[0];
    st3(q.t, o, t1);
    st3(q.ra, o, sel3(rubs, ca, zero3()));
    st3(q.rb, o, sel3(rubs, cb, zero3()));
    st(q.tangent_mass[0] + o, sel(rubs, k00, zero_));  // inverted with the batch, as the per-point rows'
    st(q.tangent_mass[1] + o, sel(rubs, k11, zero_));
    st(b.patch_mass[0] + o, sel(rubs, k11 * inv_det, zero_));
    st(b.patch_mass[1] + o, sel(rubs, -k01 * inv_det, zero_));
    st(b.patch_mass[2] + o, sel(rubs, k00 * inv_det, zero_));
    st(q.lambda_t[0] + o, sel(rubs, warm * dot(carried, t1), zero_));
    st(q.lambda_t[1] + o, sel(rubs, warm * dot(carried, t2), zero_));
    // The twist: lever arms in the contact plane, and its row's mass.
    D arm2 = zero_, twist = zero_;
    for (int i = 0; i < kMaxPoints; ++i) {
      const V3 d = sub(ras[i], ca);
      const V3 in_plane = sub(d, mul(n, dot(n, d)));
      const D arm = sel(valid[i] & rubs, vsqrt(dot(in_plane, in_plane)), zero_);
      st(b.arm[i] + o, arm);
      arm2 += arm * arm;
      twist += dot(fis[i], cross(n, d));
    }
    const D kt = dot(n, mulM(ia, n)) + dot(n, mulM(ib, n)) + cfm;
    const M turns = rubs & (arm2 > 0) & (kt > 0);
    st(b.twist_mass + o, sel(turns, one / sel(turns, kt, one), zero_));
    st(b.lambda_twist + o, sel(turns, warm * twist, zero_));
  }

  // Per-point friction: the patch's fields hold zeros.
  CAIRN_INLINE void clearPatch(ContactBatch& b, int o) {
    const D zero_ = zero();
    for (int k = 0; k < 3; ++k) st(b.patch_mass[k] + o, zero_);
    st(b.twist_mass + o, zero_);
    st(b.lambda_twist + o, zero_);
    for (int i = 0; i < kMaxPoints; ++i) st(b.arm[i] + o, zero_);
  }

  static void fill(ContactBatch& b, const ContactBatchInput& in, const ContactFillParams& p) {
    const D zero_ = zero(), one = splat(1), cfm = splat(p.cfm);
    for (int o = 0; o < kBatchLanes; o += W) {
      D count;
      for (int i = 0; i < W; ++i) count[i] = b.count[o + i];
      // Mass data: m^-1 per axis (the locks' factors), the symmetric
      // inverse inertia the sweeps read (upper triangle of the full one).
      const V3 ma = mul(ld3(in.a.lin_factor, o), ld(in.a.inv_mass + o));
      const V3 mb = mul(ld3(in.b.lin_factor, o), ld(in.b.inv_mass + o));
      st3(b.ma, o, ma);
      st3(b.mb, o, mb);
      const M3 ia = ldm(in.a.inv_inertia, o), ib = ldm(in.b.inv_inertia, o);
      stUpper(b.ia, o, ia);
      stUpper(b.ib, o, ib);
      const V3 n = ld3(in.n, o);
      st3(b.n, o, n);
      const D mu = ld(in.friction + o);
      st(b.mu + o, mu);
      st(b.cfm + o, sel(count > 0, cfm, zero_));  // a padding lane has no rows, and no CFM
      clearSweepState(b, o);
      if (p.first_substep) {  // the correction pass's figures carry over the substeps
        st(b.bias_delta + o, zero_);
        st(b.bias_lambda + o, zero_);
      }
      const V3 m_ab = add(ma, mb);
      const V3 xa = ld3(in.a.x, o), xb = ld3(in.b.x, o);
      const V3 va = ld3(in.a.v, o), wa = ld3(in.a.w, o), vb = ld3(in.b.v, o), wb = ld3(in.b.w, o);
      const D lin_n = dot(n, cmul(m_ab, n));

      V3 ran[kMaxPoints], rbn[kMaxPoints], ia_ran[kMaxPoints], ib_rbn[kMaxPoints];
      V3 ras[kMaxPoints], rbs[kMaxPoints], fis[kMaxPoints];  // patch friction's inputs
      M valid[kMaxPoints];
      for (int i = 0; i < kMaxPoints; ++i) {
        ContactBatch::Point& q = b.p[i];
        const ContactBatchInput::Point& ip = in.p[i];
        const M real = count > static_cast<double>(i);
        const V3 pa = add(xa, rotate(in.a, o, ld3(ip.local_a, o)));
        const V3 pb = add(xb, rotate(in.b, o, ld3(ip.local_b, o)));
        const V3 ra = sub(pa, xa), rb = sub(pb, xb);
        ran[i] = sel3(real, cross(ra, n), zero3());
        rbn[i] = sel3(real, cross(rb, n), zero3());
        ia_ran[i] = sel3(real, mulM(ia, ran[i]), zero3());
        ib_rbn[i] = sel3(real, mulM(ib, rbn[i]), zero3());
        const D k = lin_n + dot(ran[i], ia_ran[i]) + dot(rbn[i], ib_rbn[i]);
        const M ok = real & (k > 0);  // neither body can move along the normal here (locks): no row
        valid[i] = ok;
        const auto put = [&](double* dst, D v) { st(dst + o, sel(ok, v, zero_)); };
        const auto put3 = [&](double (*dst)[kBatchLanes], const V3& v) {
          put(dst[0], v.x);
          put(dst[1], v.y);
          put(dst[2], v.z);
        };
        put(q.valid, one);
        put3(q.ran, ran[i]);
        put3(q.rbn, rbn[i]);
        put(q.normal_mass, k + cfm);  // inverted with the batch

        putTargets(q, o, ok, dot(sub(pb, pa), n), p);
        // Restitution: the approach speed at detection, before this step's
        // forces, applied once after the solve (the restitution kernel).
        const D approach = ld(ip.approach_speed + o), e = ld(in.restitution + o);
        const M bounces = (e > 0) & (-approach > splat(p.threshold));
        put(q.bounce, sel(bounces, -e * approach, zero_));
        put(q.max_lambda, p.first_substep ? zero_ : ld(ip.max_impulse + o));
        put(q.lambda, splat(p.warm) * ld(ip.normal_impulse + o));

        // Friction: the first tangent along the sliding direction when
        // sliding, so the pyramid's corners do not favour axes; else along
        // the carried friction impulse, else any perpendicular
        // (anyPerpendicular in cairn/math.hpp: n x (x or y), normalised).
        const V3 fi = ld3(ip.friction_impulse, o);
        if (p.patch) {  // no rows here: the patch's are made below
          ras[i] = ra;
          rbs[i] = rb;
          fis[i] = sel3(ok, fi, zero3());
          st3(q.t, o, zero3());
          st3(q.ra, o, zero3());
          st3(q.rb, o, zero3());
          for (int k2 = 0; k2 < 2; ++k2) {
            st(q.tangent_mass[k2] + o, zero_);
            st(q.lambda_t[k2] + o, zero_);
          }
          continue;
        }
        const V3 vrel = sub(add(vb, cross(wb, rb)), add(va, cross(wa, ra)));
        const V3 t1 = tangent(n, vrel, fi);
        put3(q.t, t1);
        // A tangent row left out keeps a zero effective mass: no row (the
        // residual, the statistics and the exported rows skip it).
        const M rubs = ok & (mu > 0);
        const auto rowPut = [&](double* dst, D v) { st(dst + o, sel(rubs, v, zero_)); };
        // The anchors, for the tangent rows' r x t: zeros where no tangent row is solved.
        st3(q.ra, o, p.friction_rows > 0 ? sel3(rubs, ra, zero3()) : zero3());
        st3(q.rb, o, p.friction_rows > 0 ? sel3(rubs, rb, zero3()) : zero3());
        for (int k2 = 0; k2 < 2; ++k2) {
          if (k2 >= p.friction_rows) {  // not solved: zeros, nothing computed
            st(q.tangent_mass[k2] + o, zero_);
            st(q.lambda_t[k2] + o, zero_);
            continue;
          }
          const V3 t = k2 == 0 ? t1 : cross(n, t1);
          const V3 rat = cross(ra, t), rbt = cross(rb, t);
          const D kt = dot(t, cmul(m_ab, t)) + dot(rat, mulM(ia, rat)) + dot(rbt, mulM(ib, rbt));
          rowPut(q.tangent_mass[k2], kt + cfm);  // inverted with the batch (<= 0: no row)
          rowPut(q.lambda_t[k2], splat(p.warm) * dot(fi, t));
        }
      }
      if (p.patch) fillPatch(b, o, p, valid, ras, rbs, fis, ia, ib, m_ab, n, mu, va, wa, vb, wb);
      else clearPatch(b, o);
      // The normal block, padded to 4 x 4 with identity rows.
      for (int i = 0; i < kMaxPoints; ++i)
        for (int j = 0; j <= i; ++j) {
          D v = lin_n + dot(ran[i], ia_ran[j]) + dot(rbn[i], ib_rbn[j]) + (i == j ? cfm : zero_);
          v = sel(valid[i] & valid[j], v, i == j ? one : zero_);
          st(b.block[tri(i, j)] + o, v);
        }
    }
  }
};

#include "solver/joint_kernel_impl.hpp"

#undef CAIRN_INLINE

// The sweeps' kernels at the narrowest width that holds a batch's
// manifolds. A colour's manifolds fill its batches from lane 0, so only its
// last batch is partly empty, and a stack's many small colours make many
// such batches (pyramid-20: 44 of its 111 batches hold four manifolds or
// fewer, 25 of them two or fewer). A wide kernel works every lane of its
// vector whether or not it holds a manifold; the narrower ones skip the
// empty groups of lanes. Every width does the same arithmetic per lane
// (above), so a batch gives the same bits at any of them.
template <int Wide>
struct Narrowed {
  // The narrowest of 2, 4 and Wide lanes that holds every manifold of b.
  static inline int width(const ContactBatch& b) {
    if (Wide == 2) return 2;  // the portable table: nothing narrower
    int used = 0;
    for (int l = 0; l < kBatchLanes; ++l)
      if (b.count[l] > 0) used = l + 1;
    return used <= 2 ? 2 : used <= 4 && Wide > 4 ? 4 : Wide;
  }
  // call(width, first, last) over the runs of consecutive batches of one width.
  template <class Call>
  static inline void runs(const ContactBatch* batches, int begin, int end, Call&& call) {
    for (int i = begin; i < end;) {
      const int w = width(batches[i]);
      int j = i + 1;
      while (j < end && width(batches[j]) == w) ++j;
      call(w, i, j);
      i = j;
    }
  }
  // One of the table's sweeps (its arguments after the batch range are
  // the kernels' own: momentum's carry the islands' betas).
  template <auto F2, auto F4, auto FW, class... Args>
  static void sweep(ContactBatch* batches, int begin, int end, Args... args) {
    runs(batches, begin, end, [&](int w, int i, int j) { (w == 2 ? F2 : w == 4 ? F4 : FW)(batches, i, j, args...); });
  }
};

}  // namespace

// The table of this unit's kernels, a constant: a table filled at run time
// would be filled by this unit's instructions, before the CPU is asked
// what it supports (the units define it constinit).
constexpr ContactKernels makeKernels(const char* name) {
  using K = Kernel<CAIRN_KERNEL_LANES>;
  using K2 = Kernel<2>;
  using K4 = Kernel<(CAIRN_KERNEL_LANES > 4 ? 4 : CAIRN_KERNEL_LANES)>;
  using N = Narrowed<CAIRN_KERNEL_LANES>;
  return ContactKernels{name,
                        CAIRN_KERNEL_LANES,
                        &N::template sweep<&K2::warmStart, &K4::warmStart, &K::warmStart>,
                        &N::template sweep<&K2::solveNormals, &K4::solveNormals, &K::solveNormals>,
                        &N::template sweep<&K2::solveFriction, &K4::solveFriction, &K::solveFriction>,
                        &N::template sweep<&K2::momentum, &K4::momentum, &K::momentum>,
                        &N::template sweep<&K2::solveBias, &K4::solveBias, &K::solveBias>,
                        &N::template sweep<&K2::restitution, &K4::restitution, &K::restitution>,
                        &K::fill,
                        &K::refresh,
                        &JointKernel<CAIRN_KERNEL_LANES>::solveLanes,
                        &JointKernel<CAIRN_KERNEL_LANES>::momentumLanes,
                        &JointKernel<CAIRN_KERNEL_LANES>::biasLanes};
}

}  // namespace CAIRN_KERNEL_NS
}  // namespace cairn
