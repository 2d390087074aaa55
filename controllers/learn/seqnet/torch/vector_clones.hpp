#pragma once
// The training step's hand-written loops are each compiled for AVX-512, AVX2
// and the baseline, and the best the CPU has is picked at load time: the
// library itself is built for the baseline, where the batch loops would run
// four numbers at a time.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ANIMRT_VECTOR_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define ANIMRT_VECTOR_CLONES
#endif
