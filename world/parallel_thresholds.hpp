// Work below which a stage stays on the calling thread when the World has
// a worker pool (SolverSettings::threads > 1). Handing a loop over costs a
// write the waiting workers see and a barrier at its end (the pool is kept
// warm through a step, so no worker has to be woken);
// each threshold is where that began to pay on the shared 2-core machine,
// measured as its comment says. The solve's colours have their own rule
// (solver/graph_solver.cpp). Results never depend on them: the threads
// split a loop's items, and every reduction runs in storage order on one
// thread or is a maximum, whose value does not depend on the order
// (tests/unit/solver_determinism_test.cpp runs scenes past all of them on
// 1, 2 and 4 threads).
#pragma once

namespace cairn::detail {

// Pairs below which collide (world/world_contacts.cpp: the narrowphase
// and the warm start of the contacts it makes) stays on the calling
// thread. A fresh narrowphase call is 0.2 to 2 us, but a resting pair is
// recycled or kept for a tenth of that, and the second thread's contacts
// are then copied into the list (704 bytes each): with 64, an awake
// pyramid-20 (590 pairs, most recycled) collided in 0.056 ms on two
// threads against 0.038 on one, while the 5,050-box pyramid (15,000
// pairs) went from 13.9 to 9.2 ms. Since the World keeps its pool warm
// through a step (solver/worker_pool.hpp, keepWarm), a handover no longer
// waits for a worker's wake-up: at 512, pile-1000's awake steps (1,000
// pairs, recycled) collided in 0.28 ms against 0.35 at 1,024, and
// pyramid-20's awake collide was unchanged (0.156 to 0.163 ms against
// 0.157 to 0.164; docs/performance.md, "Earlier: a warm pool").
constexpr int kParallelPairs = 512;

// Moved proxies below which the broadphase's pair queries (one tree
// descent each, about a microsecond on a 5,000-box tree) stay on the
// calling thread (world/world_contacts.cpp).
constexpr int kParallelMovedProxies = 256;

// Batches below which the lanes are gathered, filled and factored on the
// calling thread (world/step_prepare.cpp). With the fill kernel a batch
// takes about half a microsecond, and a stack's batches hold one manifold
// each: column-20's twenty ran its step 8 to 14% slower on two threads
// than on one when sixteen batches were handed over, 5% at 64 (`cairn
// bench column-20 --threads 1|2 --repeat 5`), while pile-1000 (120
// batches) and the 5,050-box pyramid filled no slower.
constexpr int kParallelBatches = 64;

// Lane slots below which the impulses are stored on the calling thread
// (world/step_solve.cpp): a few nanoseconds each, against waking a worker;
// with 256, pyramid-20's store doubled on two threads.
constexpr int kParallelLanes = 4096;

// Contacts below which the watchers' depths after the step are found on
// the calling thread (world/step_diagnostics.cpp). A depth is a few tens
// of nanoseconds, and a worker idle since the solve may have to be woken:
// with 256, pile-1000's guards went from 0.08 to 0.14 ms/step on two
// threads.
constexpr int kParallelContacts = 4096;

// Shapes below which their proxies are refitted on the calling thread
// (world/world_proxies.cpp). A refit that keeps its fat box is a shape's
// box and a test, about a tenth of a microsecond (the 5,050-box pyramid's
// refit took 0.70 ms a step on one thread): with the pool kept warm, half
// a thousand of them are worth handing over, as the pairs are.
constexpr int kParallelProxies = 512;

// Awake bodies below which the velocity and position updates stay on the
// calling thread (world/step_integrate.cpp): 40 to 50 ns a body on the
// 5,050-box pyramid, 0.45 ms a step for both on one thread. The guards'
// and watchers' walks over the bodies (world/body_walk.hpp), a few to a
// few tens of nanoseconds a body each, share it. The bodies awake at the
// last islands stage are what is counted (an asleep body is a test and a
// skip): with every body slot counted at 512, an asleep pile-1000's step
// was 0.054 to 0.057 ms on two threads against 0.052 to 0.053 at 1,024;
// with the awake bodies counted here and in the proxies' refit, 0.053.
// Its awake steps integrate in 0.049 to 0.054 ms against 0.064 to 0.068.
constexpr int kParallelBodies = 512;

// Constraints (manifolds and joints) below which the PGS islands are not
// split into parts, one per thread (world/step_prepare.cpp): a part's
// sweeps are handed over once per solve, a few microseconds against the
// tens that 64 constraints take to sweep ten times.
constexpr int kParallelPartItems = 64;

}  // namespace cairn::detail
