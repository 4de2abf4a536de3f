// The kernel's evaluation (kernel/aba.hpp) compiled for AVX2 and FMA (setup.py gives this unit
// -mavx2 -mfma): four states in one register per number. kernel.cpp calls it only on a CPU that
// has both instruction sets.
#define FREEFLOAT_KERNEL_ISA avx2
#include "kernel/aba.hpp"
#include "kernel/isa.hpp"

namespace freefloat::kernel::avx2 {

void aba_one(const TreeView& tree, const Bodies<double>& bodies, BodyWork<double>* work, const double* q,
             const double* qd, const double* tau, const Wrenches* wrenches, double* qdd) {
  aba(tree, bodies, work, q, qd, tau, wrenches, qdd);
}

void aba_lanes(const TreeView& tree, const Bodies<Lanes>& bodies, BodyWork<Lanes>* work, const Lanes* q,
               const Lanes* qd, const Lanes* tau, const Wrenches* wrenches, Lanes* qdd) {
  aba(tree, bodies, work, q, qd, tau, wrenches, qdd);
}

}  // namespace freefloat::kernel::avx2
