#pragma once
// numpy.random.default_rng(seed).random() in C++: SeedSequence(seed) hashed into PCG64's 128-bit
// state, XSL-RR output, 53-bit doubles (numpy's bit_generator.pyx, pcg64.h and distributions.c).
// The stream is the one numpy documents as stable across versions, so the hovering area's samples
// are the same doubles as numpy's whichever program draws them. Private to the core: PCG64's
// state is an unsigned 128-bit integer, a GCC/Clang extension that no public header may expose.

#include <cstdint>
#include <vector>

namespace hovering::detail {

__extension__ typedef unsigned __int128 uint128;

class NumpyRandom {
public:
    /// The generator numpy.random.default_rng(seed) starts as.
    explicit NumpyRandom(std::uint64_t seed) {
        std::uint64_t s[4];
        seed_state(seed, s);
        const uint128 initstate = (uint128(s[0]) << 64) | s[1];
        const uint128 initseq = (uint128(s[2]) << 64) | s[3];
        inc_ = (initseq << 1) | 1u;
        state_ = inc_;  // 0 * mult + inc: the first step of pcg_setseq_128_srandom_r
        state_ += initstate;
        state_ = state_ * mult() + inc_;
    }
    /// The next raw 64-bit output (PCG64 XSL-RR).
    std::uint64_t next_u64() {
        state_ = state_ * mult() + inc_;
        const std::uint64_t x = std::uint64_t(state_ >> 64) ^ std::uint64_t(state_);
        const unsigned r = unsigned(state_ >> 122);
        return (x >> r) | (x << ((64 - r) & 63));
    }
    /// The next double in [0, 1), as Generator.random().
    double random() { return double(next_u64() >> 11) * (1.0 / 9007199254740992.0); }
    /// Skip delta outputs in O(log delta) steps (pcg_advance_lcg_128: the LCG's jump ahead), so a
    /// piece of a sample range starts where the whole range's stream is at its first index.
    void advance(std::uint64_t delta) {
        uint128 acc_mult = 1, acc_plus = 0, cur_mult = mult(), cur_plus = inc_;
        for (uint128 d = delta; d > 0; d >>= 1) {
            if (d & 1u) {
                acc_mult *= cur_mult;
                acc_plus = acc_plus * cur_mult + cur_plus;
            }
            cur_plus = (cur_mult + 1) * cur_plus;
            cur_mult *= cur_mult;
        }
        state_ = acc_mult * state_ + acc_plus;
    }

private:
    static uint128 mult() { return (uint128(2549297995355413924ULL) << 64) + 4865540595714422341ULL; }

    // SeedSequence (bit_generator.pyx): the seed's 32-bit words hashed into a pool of 4, mixed,
    // then drawn out as generate_state(4, uint64).
    static std::uint32_t hashmix(std::uint32_t v, std::uint32_t& hc) {
        v ^= hc;
        hc *= 0x931e8875u;
        v *= hc;
        return v ^ (v >> 16);
    }
    static std::uint32_t mix(std::uint32_t x, std::uint32_t y) {
        const std::uint32_t r = 0xca01f9ddu * x - 0x4973f715u * y;
        return r ^ (r >> 16);
    }
    static void seed_state(std::uint64_t seed, std::uint64_t out[4]) {
        std::vector<std::uint32_t> entropy;
        do {
            entropy.push_back(std::uint32_t(seed & 0xffffffffu));
            seed >>= 32;
        } while (seed != 0);
        std::uint32_t pool[4], hc = 0x43b0d7e5u;
        for (std::size_t i = 0; i < 4; ++i) pool[i] = hashmix(i < entropy.size() ? entropy[i] : 0u, hc);
        for (int s = 0; s < 4; ++s)
            for (int d = 0; d < 4; ++d)
                if (s != d) pool[d] = mix(pool[d], hashmix(pool[s], hc));
        for (std::size_t s = 4; s < entropy.size(); ++s)
            for (int d = 0; d < 4; ++d) pool[d] = mix(pool[d], hashmix(entropy[s], hc));
        std::uint32_t words[8], hb = 0x8b51f9ddu;
        for (int i = 0; i < 8; ++i) {
            std::uint32_t v = pool[i % 4] ^ hb;
            hb *= 0x58f38dedu;
            v *= hb;
            words[i] = v ^ (v >> 16);
        }
        for (int k = 0; k < 4; ++k) out[k] = std::uint64_t(words[2 * k]) | (std::uint64_t(words[2 * k + 1]) << 32);
    }

    uint128 state_ = 0, inc_ = 0;
};

}  // namespace hovering::detail
