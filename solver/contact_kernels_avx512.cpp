// The AVX-512 contact kernels: eight doubles per vector (compiled with
// -mavx512f -mavx512dq).
#define CAIRN_KERNEL_NS avx512_kernels
#define CAIRN_KERNEL_LANES 8
#include "solver/contact_kernel_impl.hpp"

namespace cairn {
extern const ContactKernels kContactKernelsAvx512;
constinit const ContactKernels kContactKernelsAvx512 = avx512_kernels::makeKernels("avx512");
}  // namespace cairn
