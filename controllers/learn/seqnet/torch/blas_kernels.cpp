#include "animrt/learn/seqnet/blas_kernels.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>

namespace animrt::seqnet {

std::string blas_kernels() {
  // Looked up at run time: libtorch links the BLAS, this library does not.
  using CoreName = char* (*)();
  auto* name = reinterpret_cast<CoreName>(::dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (name == nullptr) return "";
  const char* n = name();
  return n == nullptr ? "" : n;
}

std::string better_blas_kernels() {
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return "";
  if (blas_kernels() != "Prescott") return "";
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq")) {
    return "SkylakeX";
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
  return "";
}

void restart_with_better_blas_kernels(char** argv) {
  const std::string kernels = better_blas_kernels();
  if (kernels.empty()) return;
  ::setenv("OPENBLAS_CORETYPE", kernels.c_str(), 1);
  ::execv("/proc/self/exe", argv);
  ::unsetenv("OPENBLAS_CORETYPE");  // the restart failed: go on as before
}

}  // namespace animrt::seqnet
