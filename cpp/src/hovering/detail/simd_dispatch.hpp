#pragma once
// Which build of the SIMD kernels the core runs (internal): the one choice of every kernel that is
// compiled once per instruction set, the truncated map's lanes (truncated/lanes.cpp) and the flow's
// Taylor expansion (flow/taylor_lanes.cpp). A portable x86-64 build (HOVERING_LANES_DISPATCH, see
// CMakeLists.txt) holds each of them for its baseline, AVX2 and AVX-512; any other build holds its
// baseline only. The build is set_simd_level's, else HOVERING_SIMD's (read at first use), else the
// widest this CPU runs. Each kernel keeps a table of its builds in this order and runs entry
// simd_build(): one dispatch, whatever the number of kernels.

namespace hovering::detail {

/// Builds of every dispatched kernel this binary holds, narrowest first.
#if defined(HOVERING_LANES_DISPATCH)
inline constexpr int kSimdBuilds = 3;  // baseline, AVX2, AVX-512
#else
inline constexpr int kSimdBuilds = 1;  // the baseline only (a native or a non-x86 build)
#endif

/// Index of the selected build in a kernel's table of builds (0: the baseline); throws
/// std::invalid_argument for a bad HOVERING_SIMD, at every call until it is fixed or
/// set_simd_level chooses.
int simd_build();

/// The selected build's entry of a kernel's table of builds (kSimdBuilds entries, narrowest first).
template <class Kernels>
const Kernels& selected_build(const Kernels* const (&builds)[kSimdBuilds]) {
    return *builds[simd_build()];
}

}  // namespace hovering::detail
