// The portable contact kernels: one lane at a time, any CPU.
#define CAIRN_KERNEL_NS portable_kernels
#define CAIRN_KERNEL_LANES 1
#include "solver/contact_kernel_impl.hpp"

namespace cairn {
extern const ContactKernels kContactKernelsPortable;
constinit const ContactKernels kContactKernelsPortable = portable_kernels::makeKernels("portable");
}  // namespace cairn
