// The portable contact kernels, for any CPU: two lanes at a time, which is
// SSE2 on x86-64, NEON on AArch64, and the compiler's own lowering
// elsewhere. Not one lane: GCC 12 miscompiles masks of one-element vectors
// (docs/decisions.md).
#define CAIRN_KERNEL_NS portable_kernels
#define CAIRN_KERNEL_LANES 2
#include "solver/contact_kernel_impl.hpp"

namespace cairn {
extern const ContactKernels kContactKernelsPortable;
constinit const ContactKernels kContactKernelsPortable = portable_kernels::makeKernels("portable");
}  // namespace cairn
