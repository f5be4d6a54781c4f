// Picks the contact kernels at run time from what was built in and what
// the CPU supports (contact_kernels.hpp).
#include "solver/contact_kernels.hpp"

#include <stdexcept>
#include <string>

namespace cairn {

extern const ContactKernels kContactKernelsPortable;
#ifdef CAIRN_KERNELS_AVX2
extern const ContactKernels kContactKernelsAvx2;
#endif
#ifdef CAIRN_KERNELS_AVX512
extern const ContactKernels kContactKernelsAvx512;
#endif

const char* simdLevelName(SimdLevel level) {
  switch (level) {
    case SimdLevel::Portable: return "portable";
    case SimdLevel::Avx2: return "avx2";
    case SimdLevel::Avx512: return "avx512";
  }
  return "unknown";
}

bool simdLevelAvailable(SimdLevel level) {
  switch (level) {
    case SimdLevel::Portable: return true;
    case SimdLevel::Avx2:
#if defined(CAIRN_KERNELS_AVX2) && (defined(__x86_64__) || defined(__i386__))
      return __builtin_cpu_supports("avx2");
#else
      return false;
#endif
    case SimdLevel::Avx512:
#if defined(CAIRN_KERNELS_AVX512) && (defined(__x86_64__) || defined(__i386__))
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
#else
      return false;
#endif
  }
  return false;
}

SimdLevel bestSimdLevel() {
  static const SimdLevel best = [] {
    if (simdLevelAvailable(SimdLevel::Avx512)) return SimdLevel::Avx512;
    if (simdLevelAvailable(SimdLevel::Avx2)) return SimdLevel::Avx2;
    return SimdLevel::Portable;
  }();
  return best;
}

const ContactKernels& contactKernels(SimdLevel level) {
  if (!simdLevelAvailable(level))
    throw std::invalid_argument(std::string("contact kernels '") + simdLevelName(level) +
                                "' are not built into this library or not supported by this CPU");
  switch (level) {
#ifdef CAIRN_KERNELS_AVX512
    case SimdLevel::Avx512: return kContactKernelsAvx512;
#endif
#ifdef CAIRN_KERNELS_AVX2
    case SimdLevel::Avx2: return kContactKernelsAvx2;
#endif
    default: return kContactKernelsPortable;
  }
}

}  // namespace cairn
