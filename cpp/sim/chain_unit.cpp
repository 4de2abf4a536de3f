// The closed-chain loop's numerics as one translation unit (a unity build) without pybind11, at
// -O3: the plant (parallel.cpp) and the loop with its law (chain_loop.cpp), which calls it at
// every stage. As two units the 5R scenes ran 3 % slower; with parallel_inverse.cpp too, the unit
// took 1.13 GB of compiler memory instead of 0.78 GB (g++ 12).
#include "../parallel.cpp"
#include "chain_loop.cpp"
