/* Part of the multibin elevation-mapping library. */
#pragma once

/** MULTIBIN_VECTOR_CLONES before a function with a vectorisable per-point loop: GCC builds it for
 * AVX-512, AVX2 and the baseline x86-64 and picks one when the library loads, so one binary runs
 * the widest vectors each machine has. Every clone computes the same bits: the library is built
 * with -ffp-contract=off (AVX-512 brings fused multiply-add, which would round differently) and
 * the loops do the same operations in the same order in every lane. Empty elsewhere. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define MULTIBIN_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define MULTIBIN_VECTOR_CLONES
#endif
