#pragma once
// Which build of the SIMD lane kernels the core runs (internal): one choice for every lane kernel
// (the truncated map's, the flow's Taylor expansion), owned by truncated/iterate.cpp (HOVERING_SIMD,
// set_simd_level, else the widest level this CPU runs).

namespace hovering::detail {

/// The selected level's name ("sse2", "avx2", "avx512", ...): a static string, the same pointer
/// until the level changes.
const char* selected_simd_level();

}  // namespace hovering::detail
