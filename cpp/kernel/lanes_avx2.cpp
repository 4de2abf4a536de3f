// The kernel's evaluation (kernel/aba.hpp, which defines the entry points of kernel/isa.hpp)
// compiled for AVX2 (setup.py gives this unit -mavx2, and -ffp-contract=off as to kernel.cpp): four
// states in one register per number. kernel.cpp calls it only on a CPU that has AVX2.
#define FREEFLOAT_KERNEL_ISA avx2
#include "aba.hpp"
