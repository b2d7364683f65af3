// NEURALMESH_AVX2_CLONE compiles a hot function twice, for AVX2 and for baseline x86-64, and
// picks one when the program is loaded (GCC's target_clones, through an ifunc). Code that must
// give bitwise the same results either way is compiled without contraction into fused
// multiply-adds (AVX2 alone enables none).
//
// Not under ThreadSanitizer: the dynamic loader runs ifunc resolvers before the sanitizer's
// runtime is up, and an instrumented resolver crashes the program at start. That build runs
// the baseline code.
#ifndef NEURALMESH_CORE_AVX2_CLONE_H_
#define NEURALMESH_CORE_AVX2_CLONE_H_

#if defined(__x86_64__) && !defined(__SANITIZE_THREAD__)
#define NEURALMESH_AVX2_CLONE __attribute__((target_clones("avx2", "default")))
#else
#define NEURALMESH_AVX2_CLONE
#endif

#endif  // NEURALMESH_CORE_AVX2_CLONE_H_
