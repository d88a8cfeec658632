// Per-lane values into lanes, for kernels.cpp (included after math.h): gathered from per-lane
// records, or looked up by sphere or light index in columns.
#pragma once

#include "render/lanes/math.h"

// A one-leaf scene has at most 16 spheres: the lanes keep its per-sphere values in fixed
// columns of 16.
constexpr size_t kMaxLeafSpheres = 16;

// Lanes from one field of the lanes' records: the records are written one lane at a time (a
// vector stored to lane by lane would stall its next load).
template <class V, class F, size_t... K>
KR_LANES V lanes_of(const F& lane_value, std::index_sequence<K...>) {
    using Element = std::remove_reference_t<decltype(V{}[0])>;
    return V{Element(lane_value(K))...};
}
template <class V, class F>  // the vector of lane_value(k) for every lane k
KR_LANES V lanes_of(const F& lane_value) {
    return lanes_of<V>(lane_value, std::make_index_sequence<kLanes>{});
}
template <class T>
KR_LANES vf gather(const T (&v)[kLanes], double T::*field) {
    return lanes_of<vf>([&](size_t k) { return v[k].*field; });
}
template <class T, class I>  // an index: int or int64_t
KR_LANES vm gather(const T (&v)[kLanes], I T::*field) {
    return lanes_of<vm>([&](size_t k) { return v[k].*field; });
}
template <class T>
KR_LANES vm gather_mask(const T (&v)[kLanes], bool T::*field) {
    return lanes_of<vm>([&](size_t k) { return -lane_int(v[k].*field); });
}
template <class F>  // the three lane vectors of lane_vector(k), a Vec3, for every lane k
KR_LANES V3 lanes_of_vec3(const F& lane_vector) {
    return {lanes_of<vf>([&](size_t k) { return lane_vector(k).x; }),
            lanes_of<vf>([&](size_t k) { return lane_vector(k).y; }),
            lanes_of<vf>([&](size_t k) { return lane_vector(k).z; })};
}
template <class T>
KR_LANES V3 gather(const T (&v)[kLanes], Vec3 T::*field) {
    return lanes_of_vec3([&](size_t k) -> const Vec3& { return v[k].*field; });
}
template <class T>
KR_LANES vf gather_x(const T (&v)[kLanes], Vec2 T::*field) {
    return lanes_of<vf>([&](size_t k) { return (v[k].*field).x; });
}
template <class T>
KR_LANES vf gather_y(const T (&v)[kLanes], Vec2 T::*field) {
    return lanes_of<vf>([&](size_t k) { return (v[k].*field).y; });
}

// Values per sphere or per area light, as columns the lanes look up by index. Up to
// kMaxLeafSpheres of each (scenes of one leaf), fixed columns: eight float lanes look up by
// two register permutes (vpermps) and a blend, double lanes one load each. Larger scenes
// (kWide) keep their columns in one buffer per batch, which eight float lanes gather from
// (vgatherdps). Indices must be valid in every lane (dead lanes use 0).
template <bool kWide>
struct ColumnOf {
    real v[kMaxLeafSpheres];
    real* data() { return v; }
    const real* data() const { return v; }
};
template <>
struct ColumnOf<true> {
    real* v = nullptr;  // into the batch's buffer (WideStore)
    size_t n = 0;       // its entries
    real* data() { return v; }
    const real* data() const { return v; }
};
template <bool kWide>
struct IndexColumnOf {
    lane_int v[kMaxLeafSpheres];
    lane_int* data() { return v; }
    const lane_int* data() const { return v; }
};
template <>
struct IndexColumnOf<true> {
    lane_int* v = nullptr;
    size_t n = 0;
    lane_int* data() { return v; }
    const lane_int* data() const { return v; }
};
template <bool kWide>
struct Column3Of {
    ColumnOf<kWide> x, y, z;
    void set(size_t i, const Vec3& v) { x.data()[i] = real(v.x), y.data()[i] = real(v.y), z.data()[i] = real(v.z); }
};
#ifdef KR_LANES_V4
// Sixteen float lanes: a fixed column is one register, looked up by one vpermps (vpermd).
// Masked forms, all lanes on: GCC 12 warns of the plain forms' undefined start.
static_assert(kMaxLeafSpheres == 16, "one register of sixteen");
KR_LANES __m512i permute_index(vm index) {
    __m512i i;
    __builtin_memcpy(&i, &index, sizeof i);
    return i;
}
KR_LANES vf look_up(const ColumnOf<false>& column, vm index) {
    return _mm512_maskz_permutexvar_ps(0xffff, permute_index(index), _mm512_loadu_ps(column.v));
}
KR_LANES vm look_up(const IndexColumnOf<false>& column, vm index) {
    const __m512i v = _mm512_maskz_permutexvar_epi32(0xffff, permute_index(index), _mm512_loadu_si512(column.v));
    vm lanes;
    __builtin_memcpy(&lanes, &v, sizeof lanes);
    return lanes;
}
// A wide column of up to 64 entries: up to four registers, each pair looked up by one
// two-source permute (vpermt2ps, vpermt2d) and the pairs blended by the index's sixth bit. On
// CPUs whose gathers are microcoded that costs far less than a gather (an AMD EPYC's sweep
// stepped +20 % from 16 spheres to 17: docs/performance.md, "Switch points"). The registers
// may read past the column's end: WideStore pads its buffers.
constexpr size_t kPermutedEntries = 64;
KR_LANES __m512 pair_look_up(const real* v, __m512i index) {
    return _mm512_maskz_permutex2var_ps(0xffff, _mm512_loadu_ps(v), index, _mm512_loadu_ps(v + 16));
}
KR_LANES __m512i pair_look_up(const lane_int* v, __m512i index) {
    return _mm512_maskz_permutex2var_epi32(0xffff, _mm512_loadu_si512(v), index, _mm512_loadu_si512(v + 16));
}
template <class T>
KR_LANES auto wide_look_up(const T* v, size_t n, vm index) {
    const __m512i i = permute_index(index);
    if (n <= kPermutedEntries / 2) return pair_look_up(v, i);
    const auto low = pair_look_up(v, i), high = pair_look_up(v + 32, i);
    const __mmask16 upper = _mm512_mask_cmpgt_epi32_mask(0xffff, i, _mm512_set1_epi32(31));
    if constexpr (std::is_same_v<T, real>) return _mm512_mask_blend_ps(upper, low, high);
    else return _mm512_mask_blend_epi32(upper, low, high);
}
KR_LANES vf look_up(const ColumnOf<true>& column, vm index) {
    if (column.n <= kPermutedEntries) return wide_look_up(column.v, column.n, index);
    return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff, permute_index(index), column.v, 4);
}
KR_LANES vm look_up(const IndexColumnOf<true>& column, vm index) {
    const __m512i v =
        column.n <= kPermutedEntries
            ? wide_look_up(column.v, column.n, index)
            : _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), 0xffff, permute_index(index), column.v, 4);
    vm lanes;
    __builtin_memcpy(&lanes, &v, sizeof lanes);
    return lanes;
}
#elif defined(KR_LANES_FLOAT)
static_assert(kMaxLeafSpheres == 16, "two registers of eight");
KR_LANES __m256i permute_index(vm index) {
    __m256i i;
    __builtin_memcpy(&i, &index, sizeof i);
    return i;
}
KR_LANES vf look_up(const ColumnOf<false>& column, vm index) {
    const __m256i i = permute_index(index);
    const __m256 low = _mm256_permutevar8x32_ps(_mm256_loadu_ps(column.v), i);
    const __m256 high = _mm256_permutevar8x32_ps(_mm256_loadu_ps(column.v + 8), i);
    return select(index > 7, high, low);
}
KR_LANES vm look_up(const IndexColumnOf<false>& column, vm index) {
    const __m256i i = permute_index(index);
    const __m256i low = _mm256_permutevar8x32_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(column.v)), i);
    const __m256i high =
        _mm256_permutevar8x32_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(column.v + 8)), i);
    vm low_lanes, high_lanes;
    __builtin_memcpy(&low_lanes, &low, sizeof low_lanes);
    __builtin_memcpy(&high_lanes, &high, sizeof high_lanes);
    return index > 7 ? high_lanes : low_lanes;
}
KR_LANES vf look_up(const ColumnOf<true>& column, vm index) {
    return _mm256_i32gather_ps(column.v, permute_index(index), 4);
}
KR_LANES vm look_up(const IndexColumnOf<true>& column, vm index) {
    const __m256i v = _mm256_i32gather_epi32(reinterpret_cast<const int*>(column.v), permute_index(index), 4);
    vm lanes;
    __builtin_memcpy(&lanes, &v, sizeof lanes);
    return lanes;
}
#else
template <bool kWide>
KR_LANES vf look_up(const ColumnOf<kWide>& column, vm index) {
    return lanes_of<vf>([&](size_t k) { return column.data()[index[k]]; });
}
template <bool kWide>
KR_LANES vm look_up(const IndexColumnOf<kWide>& column, vm index) {
    return lanes_of<vm>([&](size_t k) { return column.data()[index[k]]; });
}
#endif
template <bool kWide>
KR_LANES V3 look_up(const Column3Of<kWide>& column, vm index) {
    return {look_up(column.x, index), look_up(column.y, index), look_up(column.z, index)};
}

// A wide table's columns, in one buffer per batch: `bind` points each column at its part.
// For the sixteen lanes the buffers end in 64 entries more, which a look-up of the last
// column in four registers may read (never use).
struct WideStore {
#ifdef KR_LANES_V4
    static constexpr size_t kPad = kPermutedEntries;
#else
    static constexpr size_t kPad = 0;
#endif
    std::vector<real> reals;
    std::vector<lane_int> ints;
    size_t n = 0, next_real = 0, next_int = 0;
    explicit WideStore(size_t count, size_t real_columns, size_t int_columns)
        : reals(count * real_columns + kPad), ints(count * int_columns + kPad), n(count) {}
    void bind(ColumnOf<true>& c) { c.v = reals.data() + n * next_real++, c.n = n; }
    void bind(IndexColumnOf<true>& c) { c.v = ints.data() + n * next_int++, c.n = n; }
    void bind(Column3Of<true>& c) { bind(c.x), bind(c.y), bind(c.z); }
};

// What a vertex on each sphere reads: its geometry and its material's values, and (use) the
// numbers it draws (vertex_numbers_used, less Russian roulette, which goes by depth alone).
// The material's parameters are a column each, in the order of scene.h's kMaterialColours and
// kMaterialNumbers (every member material_params names), filled by `set_material`.
template <bool kWide>
struct SphereTable {
    Column3Of<kWide> centre;
    ColumnOf<kWide> radius;
    Column3Of<kWide> colour[kMaterialColours.count];
    ColumnOf<kWide> number[kMaterialNumbers.count];
    IndexColumnOf<kWide> type, use;
    static constexpr size_t kReals = 4 + 3 * kMaterialColours.count + kMaterialNumbers.count, kInts = 2;
    void bind(WideStore& store) {
        store.bind(centre), store.bind(radius);
        for (auto& c : colour) store.bind(c);
        for (auto& c : number) store.bind(c);
        store.bind(type), store.bind(use);
    }
    // Sphere s's material: its type and parameters (each column's member a constant, so each
    // is one store, as a batch fills the table).
    void set_material(size_t s, const Material& material) {
        set_material(s, material, std::make_index_sequence<kMaterialColours.count>{},
                     std::make_index_sequence<kMaterialNumbers.count>{});
    }
    template <size_t... C, size_t... N>
    void set_material(size_t s, const Material& material, std::index_sequence<C...>, std::index_sequence<N...>) {
        (colour[C].set(s, material.*kMaterialColours.members[C]), ...);
        ((number[N].data()[s] = real(material.*kMaterialNumbers.members[N])), ...);
        type.data()[s] = lane_int(material.type);
    }
};
// The area lights' values, by light.
template <bool kWide>
struct LightTable {
    Column3Of<kWide> centre, radiance;
    ColumnOf<kWide> radius, select_prob;
    IndexColumnOf<kWide> sphere;
    static constexpr size_t kReals = 8, kInts = 1;
    void bind(WideStore& store) {
        store.bind(centre), store.bind(radiance), store.bind(radius), store.bind(select_prob), store.bind(sphere);
    }
};
KR_LANES vm of_type(vm type, MaterialType wanted) { return type == lane_int(wanted); }

// A vertex's material as vertex.h reads it: the lanes' spheres' columns, a parameter by its
// member (rho gathered once per vertex by the path loop, which reads it for light samples too).
template <class Table>
struct LaneMaterial {
    const Table& table;
    vm sphere, type;
    V3 rho_;
    KR_LANES vm is(MaterialType wanted) const { return of_type(type, wanted); }
    template <auto member>
    KR_LANES auto get() const {
        if constexpr (std::is_same_v<decltype(member), Color Material::*>) {
            constexpr size_t column = kMaterialColours.index(member);
            static_assert(column < kMaterialColours.count, "not a parameter of material_params");
            if constexpr (member == &Material::rho) return rho_;
            else return look_up(table.colour[column], sphere);
        } else {
            constexpr size_t column = kMaterialNumbers.index(member);
            static_assert(column < kMaterialNumbers.count, "not a parameter of material_params");
            return look_up(table.number[column], sphere);
        }
    }
};
// The gather of rho that LaneMaterial's rho_ takes.
template <class Table>
KR_LANES V3 look_up_rho(const Table& table, vm sphere) {
    constexpr size_t column = kMaterialColours.index(&Material::rho);
    return look_up(table.colour[column], sphere);
}
