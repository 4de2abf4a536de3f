// The kernel's entry points per instruction set: kernel/aba.hpp's evaluation compiled for the
// baseline of the platform (kernel.cpp) and for AVX2 (lanes_avx2.cpp, called only on a CPU that
// has it: kernel.cpp checks at run time, so the module imports on any x86-64). Both round every
// product and sum on its own (setup.py: -ffp-contract=off), so that all four give one state the
// same numbers, bit for bit, alone or in a lane.
#pragma once

#include "tree.hpp"
#include "wrench.hpp"

// One state: qdd (nv,) at (q, qd, tau) with the bodies' numbers; wrenches: one list or null.
// Four states, one per lane, in structure of arrays: q (nq,), qd, tau, qdd (nv,) of Lanes, the
// bodies per lane; wrenches: one list per lane or null.
#define FREEFLOAT_KERNEL_ENTRIES                                                                           \
  void aba_one(const TreeView& tree, const Bodies<double>& bodies, BodyWork<double>* work, const double* q, \
               const double* qd, const double* tau, const Wrenches* wrenches, double* qdd);                \
  void aba_lanes(const TreeView& tree, const Bodies<Lanes>& bodies, BodyWork<Lanes>* work, const Lanes* q,  \
                 const Lanes* qd, const Lanes* tau, const Wrenches* wrenches, Lanes* qdd);

namespace freefloat::kernel {
namespace baseline {
FREEFLOAT_KERNEL_ENTRIES
}
namespace avx2 {
FREEFLOAT_KERNEL_ENTRIES
}
}  // namespace freefloat::kernel

#undef FREEFLOAT_KERNEL_ENTRIES
