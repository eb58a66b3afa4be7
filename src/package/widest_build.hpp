// The decoders' builds for x86-64 levels (predicted_normals.cpp, predictive_node.cpp): one function compiled
// for AVX-512 (x86-64-v4), AVX2 and the baseline (SSE2), all giving the same bits, and the choice among them
// at run time.
#pragma once

#include <utility>

namespace lodstream::package {

// Calls the widest of the three builds that this CPU runs with `args`. Cost: libgcc's CPU model read per
// call (two loads and tests) and an indirect call.
template <typename F, typename... Args>
inline void call_widest_build(F* avx512, F* avx2, F* baseline, Args&&... args) {
  F* const build = __builtin_cpu_supports("x86-64-v4") ? avx512
                   : __builtin_cpu_supports("avx2")    ? avx2
                                                       : baseline;
  build(std::forward<Args>(args)...);
}

}  // namespace lodstream::package
