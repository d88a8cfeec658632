// Sobol numbers in lanes, for kernels.cpp (included after math.h): the Sobol dimensions of
// the lanes' samplers drawn together, as Sampler (sampler.h) draws them one at a time.
#pragma once

#include "render/lanes/math.h"

#if defined(KR_LANES_V4)
// Whether the CPU has GFNI, for the sixteen lanes' bit reversal below (asked once).
inline bool cpu_has_gfni() {
    static const bool has = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("gfni") != 0;
    }();
    return has;
}

// sampler.h's reverse_bits for sixteen lanes of words: bytes swapped by one byte shuffle, then
// the bits of each byte reversed: where the CPU has GFNI (cpu_has_gfni), by one
// affine byte transform whose matrix mirrors the byte (vgf2p8affineqb, by inline assembly:
// these kernels are compiled for x86-64-v4, which has no GFNI); else by a 16-entry table per
// nibble (vpshufb), against the generic code's 16 shift-and-mask steps. Not forced inline, as
// below; trace_paths inlines it all the same.
template <bool kGfni>
struct LaneBitReverse16 {
    static inline vw apply(vw x) {
        const __m512i swap = _mm512_set4_epi32(0x0c0d0e0f, 0x08090a0b, 0x04050607, 0x00010203);
        __m512i v;
        __builtin_memcpy(&v, &x, sizeof v);
        v = _mm512_shuffle_epi8(v, swap);
        if constexpr (kGfni) {
            // bit i of each byte = bit 7 - i: matrix row 7 - i (byte 7 - i of the word) is 1 << i
            const __m512i mirror = _mm512_set1_epi64(0x8040201008040201ll);
            __asm__("vgf2p8affineqb $0, %1, %0, %0" : "+v"(v) : "v"(mirror));
        } else {
            const __m512i table = _mm512_set4_epi32(0x0f070b03, 0x0d050901, 0x0e060a02, 0x0c040800);
            const __m512i low_nibble = _mm512_set1_epi8(0x0f);
            const __m512i low = _mm512_and_si512(v, low_nibble);
            const __m512i high = _mm512_and_si512(_mm512_srli_epi16(v, 4), low_nibble);
            v = _mm512_or_si512(_mm512_slli_epi16(_mm512_shuffle_epi8(table, low), 4), _mm512_shuffle_epi8(table, high));
        }
        __builtin_memcpy(&x, &v, sizeof x);
        return x;
    }
};
using LaneBitReverse = LaneBitReverse16<false>;
#elif defined(KR_LANES_V3)
// sampler.h's reverse_bits for lanes of words: bytes swapped by one byte shuffle, then the
// bits of each byte reversed by a 16-entry table per nibble (vpshufb), against three
// shift-and-mask steps. Not forced inline: sampler.h's SobolDimension, compiled for any
// x86-64, calls it, and GCC inlines a forced call only between matching instruction sets;
// in trace_lanes it is inlined all the same.
struct LaneBitReverse {
    template <class U>
    static inline U apply(U x) {
        static_assert(sizeof(U) == 16 || sizeof(U) == 32);
        if constexpr (sizeof(U) == 32) {
            const __m256i swap = _mm256_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7,
                                                  6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12);
            const __m256i table = _mm256_setr_epi8(0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15, 0, 8, 4, 12,
                                                   2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15);
            const __m256i low_nibble = _mm256_set1_epi8(0x0f);
            __m256i v;
            __builtin_memcpy(&v, &x, sizeof v);
            v = _mm256_shuffle_epi8(v, swap);
            const __m256i low = _mm256_and_si256(v, low_nibble);
            const __m256i high = _mm256_and_si256(_mm256_srli_epi16(v, 4), low_nibble);
            v = _mm256_or_si256(_mm256_slli_epi16(_mm256_shuffle_epi8(table, low), 4), _mm256_shuffle_epi8(table, high));
            __builtin_memcpy(&x, &v, sizeof x);
        } else {
            const __m128i swap = _mm_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12);
            const __m128i table = _mm_setr_epi8(0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15);
            const __m128i low_nibble = _mm_set1_epi8(0x0f);
            __m128i v;
            __builtin_memcpy(&v, &x, sizeof v);
            v = _mm_shuffle_epi8(v, swap);
            const __m128i low = _mm_and_si128(v, low_nibble);
            const __m128i high = _mm_and_si128(_mm_srli_epi16(v, 4), low_nibble);
            v = _mm_or_si128(_mm_slli_epi16(_mm_shuffle_epi8(table, low), 4), _mm_shuffle_epi8(table, high));
            __builtin_memcpy(&x, &v, sizeof x);
        }
        return x;
    }
};
#else
using LaneBitReverse = BitReverse;
#endif
template <class U, class Reverse = LaneBitReverse>
using LaneSobol = SobolDimension<U, Reverse>;

// Calls `draw` with the bit reversal the lanes take on this CPU (a type, for LaneSobol): the
// GFNI one in the sixteen lanes where the CPU has it.
#define KR_LANES_LAMBDA __attribute__((always_inline))  // the lambdas' lanes cross no call either
template <class Draw>
KR_LANES auto with_lane_bit_reverse(Draw&& draw) {
#if defined(KR_LANES_V4)
    if (cpu_has_gfni()) return draw(LaneBitReverse16<true>{});
#endif
    return draw(LaneBitReverse{});
}

// The five numbers of a path vertex (Sampler::next_vertex) of the lanes' Sobol samplers at
// once: their dimensions d (light choice), d + 1 (light point), d + 2 (lobe), d + 3 (BSDF
// direction) and d + 4 (roulette), each lane at its own d. The per-lane part keeps the numbers
// its vertex reads, as the one-path sampler draws only those; a number no lane reads (`use`,
// Sampler::VertexUse bits) is 0 in every lane and not drawn: the lobe in the double lanes,
// any of the five in the single-precision ones, which draw each dimension on its own.
struct VertexLanes {
    vf light_pick, light_x, light_y, lobe, bsdf_x, bsdf_y, roulette;
};
#ifdef KR_LANES_FLOAT
// A 32-bit binary fraction to a float in (0, 1): its first 23 bits, then the centre of that
// 2^-23 interval (exact in single precision, so never 0 nor 1).
KR_LANES vf unit_lanes(vw fraction) {
    return (__builtin_convertvector(vm(fraction >> 9), vf) + 0.5f) * 0x1.0p-23f;
}
KR_LANES VertexLanes sobol_vertex_lanes(vw key, vw index_reversed, vw d, unsigned use) {
    return with_lane_bit_reverse([&](auto reverse) KR_LANES_LAMBDA {
        using Sobol = LaneSobol<vw, decltype(reverse)>;
        VertexLanes v{};
        if (use & Sampler::use_light_pick) v.light_pick = unit_lanes(Sobol(key, index_reversed, d).x());
        if (use & Sampler::use_light) {
            const Sobol light(key, index_reversed, d + 1);
            v.light_x = unit_lanes(light.x()), v.light_y = unit_lanes(light.y());
        }
        if (use & Sampler::use_lobe) v.lobe = unit_lanes(Sobol(key, index_reversed, d + 2).x());
        if (use & Sampler::use_bsdf) {
            const Sobol bsdf(key, index_reversed, d + 3);
            v.bsdf_x = unit_lanes(bsdf.x()), v.bsdf_y = unit_lanes(bsdf.y());
        }
        if (use & Sampler::use_roulette) v.roulette = unit_lanes(Sobol(key, index_reversed, d + 4).x());
        return v;
    });
}
#else
// Two dimensions of the four lanes share a register of eight words.
typedef uint32_t v8w __attribute__((vector_size(32)));
KR_LANES vf unit_lanes(vw fraction) {  // Sampler::to_unit, exactly: the words convert exactly
    typedef int32_t v4i __attribute__((vector_size(16)));
    const v4i centred = v4i(fraction ^ 0x80000000u);  // AVX2 converts signed words only
    return (__builtin_convertvector(centred, vf) + 2147483648.5) * 0x1.0p-32;
}
KR_LANES v8w pair(vw low, vw high) { return __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7); }
KR_LANES vf unit_low(v8w words) { return unit_lanes(__builtin_shufflevector(words, words, 0, 1, 2, 3)); }
KR_LANES vf unit_high(v8w words) { return unit_lanes(__builtin_shufflevector(words, words, 4, 5, 6, 7)); }
KR_LANES VertexLanes sobol_vertex_lanes(vw key, vw index_reversed, vw d, unsigned use) {
    VertexLanes v;
    const bool lobe = use & Sampler::use_lobe;
    const v8w key2 = pair(key, key), index2 = pair(index_reversed, index_reversed);
    const LaneSobol<v8w> light_bsdf(key2, index2, pair(d + 1, d + 3));
    const v8w x = light_bsdf.x(), y = light_bsdf.y();
    v.light_x = unit_low(x), v.bsdf_x = unit_high(x);
    v.light_y = unit_low(y), v.bsdf_y = unit_high(y);
    const v8w pick_roulette = LaneSobol<v8w>(key2, index2, pair(d, d + 4)).x();
    v.light_pick = unit_low(pick_roulette), v.roulette = unit_high(pick_roulette);
    v.lobe = lobe ? unit_lanes(LaneSobol<vw>(key, index_reversed, d + 2).x()) : vf{};
    return v;
}
#endif
