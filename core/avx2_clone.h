// NEURALMESH_AVX2_CLONE compiles a hot function twice, for AVX2 and for baseline x86-64, and
// picks one when the program is loaded (GCC's target_clones, through an ifunc). Code that must
// give bitwise the same results either way is compiled without contraction into fused
// multiply-adds (AVX2 alone enables none).
//
// Not under ThreadSanitizer: the dynamic loader runs ifunc resolvers before the sanitizer's
// runtime is up, and an instrumented resolver crashes the program at start. Not with clang
// (the fuzz builds, scripts/fuzz.sh): clang 14 emits the clones only where the attribute is
// on the definition, and calls from other files then find no symbol at link time. Those builds
// run the baseline code.
#ifndef NEURALMESH_CORE_AVX2_CLONE_H_
#define NEURALMESH_CORE_AVX2_CLONE_H_

#if defined(__x86_64__) && !defined(__SANITIZE_THREAD__) && !defined(__clang__)
#define NEURALMESH_AVX2_CLONE __attribute__((target_clones("avx2", "default")))
#else
#define NEURALMESH_AVX2_CLONE
#endif

#endif  // NEURALMESH_CORE_AVX2_CLONE_H_
