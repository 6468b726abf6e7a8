#pragma once
// The SIMD level the core runs: one choice for every kernel built for several instruction sets
// (the truncated map's lanes, the flow's Taylor expansion). A portable build holds them for SSE2,
// AVX2 and AVX-512 and runs the widest this CPU runs; HOVERING_SIMD=sse2|avx2|avx512|auto, read at
// the first use of a kernel, or set_simd_level forces one. A native build has its own level only.

#include <string>
#include <vector>

namespace hovering {

/// Instruction set of the selected kernels: "sse2", "avx2", "avx512" (a native build: its own).
std::string simd_level();
/// The levels of this build that this CPU runs, narrowest first (names as simd_level()).
std::vector<std::string> simd_levels();
/// Select the kernels' level by name ("" or "auto": the widest this CPU runs); throws
/// std::invalid_argument naming the allowed levels. Without a call: HOVERING_SIMD, else auto.
void set_simd_level(const std::string& level);
/// Doubles per SIMD packet of the truncated map's lane kernel at the selected level (8 AVX-512,
/// 4 AVX2, 2 SSE2, 1 none).
int simd_width();
/// Whether the truncated map's lane kernel at the selected level uses 4-wide (AVX2) or wider vectors.
bool simd_is_avx2();

}  // namespace hovering
