#pragma once
// The BLAS kernels libtorch's matrix products run on. Debian's OpenBLAS
// picks its kernels by CPU model at load time and falls back to its
// generic SSE3 ones ("Prescott") on a model it does not know, such as
// recent Xeons under KVM: the sequence network then trains about 1.5
// times slower than with the AVX-512 kernels the CPU has. The choice can
// only be made before the library loads (OPENBLAS_CORETYPE), so a program
// that trains restarts itself once with it set.

#include <string>

namespace animrt::seqnet {

// The OpenBLAS kernel set in use ("SkylakeX", "Haswell", "Prescott", ...),
// or "" when the BLAS is not OpenBLAS.
std::string blas_kernels();

// The kernel set to ask for on this CPU when OpenBLAS fell back to its
// generic one: "SkylakeX" with AVX-512 (F, BW, VL, DQ), "Haswell" with
// AVX2 and FMA; "" when nothing is to be changed (another BLAS, a known
// CPU, OPENBLAS_CORETYPE already set, or no such instructions).
std::string better_blas_kernels();

// When better_blas_kernels() names a set: sets OPENBLAS_CORETYPE and
// executes this program again with the same arguments (does not return).
// Returns if there is nothing to change or the restart fails.
void restart_with_better_blas_kernels(char** argv);

}  // namespace animrt::seqnet
