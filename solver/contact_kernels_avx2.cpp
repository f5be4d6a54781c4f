// The AVX2 contact kernels: four doubles per vector (compiled with -mavx2).
#define CAIRN_KERNEL_NS avx2_kernels
#define CAIRN_KERNEL_LANES 4
#include "solver/contact_kernel_impl.hpp"

namespace cairn {
extern const ContactKernels kContactKernelsAvx2;
constinit const ContactKernels kContactKernelsAvx2 = avx2_kernels::makeKernels("avx2");
}  // namespace cairn
