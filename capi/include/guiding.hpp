// guiding.hpp: a header-only C++17 wrapper of guiding.h. RAII handles
// (moveable, not copyable: copy a guide through save and load), errors as
// guiding::Error exceptions carrying the status, arrays as guiding::span.
// Written by hand over the generated C header; the names are the C API's
// without the prefix (guiding_glt_sample -> guiding::Glt::sample).
#ifndef GUIDING_HPP
#define GUIDING_HPP

#include "guiding.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace guiding {

// A failed call: its status and the crate's message.
class Error : public std::runtime_error {
public:
    Error(GuidingStatus status, const char *message) : std::runtime_error(message), status_(status) {}
    GuidingStatus status() const noexcept { return status_; }

private:
    GuidingStatus status_;
};

// Throws the thread's last error for a status other than OK.
inline void check(GuidingStatus status) {
    if (status != GUIDING_STATUS_OK) throw Error(status, guiding_last_error());
}

// A view of contiguous elements (std::span is C++20).
template <typename T>
class span {
public:
    constexpr span() noexcept = default;
    constexpr span(T *data, std::size_t size) noexcept : data_(data), size_(size) {}
    template <typename U, typename A>
    span(const std::vector<U, A> &v) noexcept : data_(v.data()), size_(v.size()) {}
    template <typename U, typename A>
    span(std::vector<U, A> &v) noexcept : data_(v.data()), size_(v.size()) {}
    template <typename U, std::size_t N>
    constexpr span(std::array<U, N> &a) noexcept : data_(a.data()), size_(N) {}
    template <typename U, std::size_t N>
    constexpr span(const std::array<U, N> &a) noexcept : data_(a.data()), size_(N) {}
    constexpr T *data() const noexcept { return data_; }
    constexpr std::size_t size() const noexcept { return size_; }

private:
    T *data_ = nullptr;
    std::size_t size_ = 0;
};

using Vec3 = std::array<float, 3>;
using ShadingContext = GuidingShadingContext;
using LightSample = GuidingLightSample;
using GltConfig = GuidingGltConfig;
using RecordOutcome = GuidingRecordOutcome;
using RefineOutcome = GuidingRefineOutcome;
using DirectionSample = GuidingDirectionSample;
using SdTreeConfig = GuidingSdTreeConfig;
using FieldConfig = GuidingFieldConfig;

// A context at `position` on a surface with `normal` (zeros: none), lit by
// every light.
inline ShadingContext shading_context(const Vec3 &position, const Vec3 &normal = {0, 0, 0}) {
    return ShadingContext{{position[0], position[1], position[2]},
                          {normal[0], normal[1], normal[2]},
                          GUIDING_ALL_LIGHTS,
                          GUIDING_ALL_LIGHTS};
}

// The crate's default GLT configuration.
inline GltConfig default_glt_config() {
    GltConfig c;
    check(guiding_glt_config_default(&c));
    return c;
}

// The crate's default SD-tree configuration (PPG's), and Müller's improved one.
inline SdTreeConfig default_sd_tree_config() {
    SdTreeConfig c;
    check(guiding_sd_tree_config_default(&c));
    return c;
}
inline SdTreeConfig improved_sd_tree_config() {
    SdTreeConfig c;
    check(guiding_sd_tree_config_improved(&c));
    return c;
}
// The crate's default field configuration.
inline FieldConfig default_field_config() {
    FieldConfig c;
    check(guiding_field_config_default(&c));
    return c;
}

namespace detail {
struct FreeEmitters {
    void operator()(GuidingEmitters *p) const noexcept { guiding_emitters_free(p); }
};
struct FreeLightTree {
    void operator()(GuidingLightTree *p) const noexcept { guiding_light_tree_free(p); }
};
struct FreeGlt {
    void operator()(GuidingGlt *p) const noexcept { guiding_glt_free(p); }
};
struct FreeSdTree {
    void operator()(GuidingSdTree *p) const noexcept { guiding_sd_tree_free(p); }
};
struct FreeField {
    void operator()(GuidingField *p) const noexcept { guiding_field_free(p); }
};
struct FreeSnapshot {
    void operator()(GuidingSnapshot *p) const noexcept { guiding_snapshot_free(p); }
};
// Bytes the crate handed out, copied into a vector and freed.
inline std::vector<std::uint8_t> take(GuidingBuffer &b) {
    std::vector<std::uint8_t> bytes(b.data, b.data + b.len);
    guiding_buffer_free(&b);
    return bytes;
}
}  // namespace detail

// A scene's emitters; each add returns the emitter's light index.
class Emitters {
public:
    Emitters() {
        GuidingEmitters *p = nullptr;
        check(guiding_emitters_new(&p));
        handle_.reset(p);
    }
    std::uint32_t add_point(const Vec3 &position, float power) {
        std::uint32_t i = 0;
        check(guiding_emitters_add_point(get(), position.data(), power, &i));
        return i;
    }
    std::uint32_t add_sphere(const Vec3 &center, float radius, float power) {
        std::uint32_t i = 0;
        check(guiding_emitters_add_sphere(get(), center.data(), radius, power, &i));
        return i;
    }
    std::uint32_t add_spot(const Vec3 &position, const Vec3 &direction, float cos_falloff_start,
                           float cos_falloff_end, float power) {
        std::uint32_t i = 0;
        check(guiding_emitters_add_spot(get(), position.data(), direction.data(), cos_falloff_start,
                                        cos_falloff_end, power, &i));
        return i;
    }
    std::uint32_t add_triangle(const Vec3 &p0, const Vec3 &p1, const Vec3 &p2, float power,
                               bool two_sided = false) {
        const float v[9] = {p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], p2[0], p2[1], p2[2]};
        std::uint32_t i = 0;
        check(guiding_emitters_add_triangle(get(), v, power, two_sided, &i));
        return i;
    }
    std::uint32_t add_quad(const Vec3 &corner, const Vec3 &edge_u, const Vec3 &edge_v, float power,
                           bool two_sided = false) {
        std::uint32_t i = 0;
        check(guiding_emitters_add_quad(get(), corner.data(), edge_u.data(), edge_v.data(), power,
                                        two_sided, &i));
        return i;
    }
    std::uint32_t add_disk(const Vec3 &center, const Vec3 &normal, float radius, float power,
                           bool two_sided = false) {
        std::uint32_t i = 0;
        check(guiding_emitters_add_disk(get(), center.data(), normal.data(), radius, power, two_sided, &i));
        return i;
    }
    std::size_t size() const noexcept { return guiding_emitters_count(handle_.get()); }
    GuidingEmitters *get() const noexcept { return handle_.get(); }

private:
    std::unique_ptr<GuidingEmitters, detail::FreeEmitters> handle_;
};

// The light tree over a scene's emitters.
class LightTree {
public:
    explicit LightTree(const Emitters &emitters, std::uint32_t heuristic = GUIDING_HEURISTIC_SARH) {
        GuidingLightTree *p = nullptr;
        check(guiding_light_tree_build(emitters.get(), heuristic, &p));
        handle_.reset(p);
    }
    static LightTree load(span<const std::uint8_t> bytes) {
        GuidingLightTree *p = nullptr;
        check(guiding_light_tree_load(bytes.data(), bytes.size(), &p));
        return LightTree(p);
    }
    std::vector<std::uint8_t> save() const {
        GuidingBuffer b;
        check(guiding_light_tree_save(get(), &b));
        return detail::take(b);
    }
    std::uint32_t emitter_count() const noexcept { return guiding_light_tree_emitter_count(get()); }
    GuidingLightTree *get() const noexcept { return handle_.get(); }

private:
    explicit LightTree(GuidingLightTree *p) : handle_(p) {}
    std::unique_ptr<GuidingLightTree, detail::FreeLightTree> handle_;
};

// The Guiding Light Tree. sample, pmf and record_light may run from many
// threads at once; refine, clear_records and merge wait for them.
class Glt {
public:
    Glt(const LightTree &tree, const Vec3 &lower, const Vec3 &upper, const GltConfig &config = default_glt_config()) {
        GuidingGlt *p = nullptr;
        check(guiding_glt_new(tree.get(), lower.data(), upper.data(), &config, &p));
        handle_.reset(p);
    }
    static Glt load(const LightTree &tree, span<const std::uint8_t> bytes) {
        GuidingGlt *p = nullptr;
        check(guiding_glt_load(tree.get(), bytes.data(), bytes.size(), &p));
        return Glt(p);
    }
    std::vector<std::uint8_t> save() const {
        GuidingBuffer b;
        check(guiding_glt_save(get(), &b));
        return detail::take(b);
    }
    // A light at `ctx` for `u` in [0, 1); light GUIDING_NO_LIGHT (pmf 0)
    // when nothing can be sampled there.
    LightSample sample(const ShadingContext &ctx, float u) const {
        LightSample s;
        check(guiding_glt_sample(get(), &ctx, u, &s));
        return s;
    }
    float pmf(const ShadingContext &ctx, std::uint32_t light) const {
        float p = 0;
        check(guiding_glt_pmf(get(), &ctx, light, &p));
        return p;
    }
    void sample(span<const ShadingContext> ctx, span<const float> u, span<LightSample> out) const {
        if (ctx.size() != u.size() || ctx.size() != out.size())
            throw Error(GUIDING_STATUS_INVALID_ARGUMENT, "sample: ctx, u and out differ in length");
        check(guiding_glt_sample_batch(get(), ctx.data(), u.data(), ctx.size(), out.data()));
    }
    void pmf(span<const ShadingContext> ctx, span<const std::uint32_t> light, span<float> out) const {
        if (ctx.size() != light.size() || ctx.size() != out.size())
            throw Error(GUIDING_STATUS_INVALID_ARGUMENT, "pmf: ctx, light and out differ in length");
        check(guiding_glt_pmf_batch(get(), ctx.data(), light.data(), ctx.size(), out.data()));
    }
    // Records a light sample's estimate (see guiding_glt_record_light).
    RecordOutcome record_light(const ShadingContext &ctx, std::uint32_t light, float value) const {
        RecordOutcome o = GUIDING_RECORD_OUTCOME_RECORDED;
        check(guiding_glt_record_light(get(), &ctx, light, value, &o));
        return o;
    }
    RefineOutcome refine() {
        RefineOutcome r;
        check(guiding_glt_refine(get(), &r));
        return r;
    }
    void clear_records() { check(guiding_glt_clear_records(get())); }
    void merge(const Glt &other) { check(guiding_glt_merge(get(), other.get())); }
    std::uint32_t light_count() const noexcept { return guiding_glt_light_count(get()); }
    std::uint32_t iteration() const noexcept { return guiding_glt_iteration(get()); }
    std::uint64_t dropped_records() const noexcept { return guiding_glt_dropped_records(get()); }
    GuidingGlt *get() const noexcept { return handle_.get(); }

private:
    explicit Glt(GuidingGlt *p) : handle_(p) {}
    std::unique_ptr<GuidingGlt, detail::FreeGlt> handle_;
};

// A GPU snapshot of what a GLT or a field learned: its plain arrays stay
// valid while it lives.
class Snapshot {
public:
    GuidingSnapshotArrays arrays() const {
        GuidingSnapshotArrays a;
        check(guiding_snapshot_arrays(handle_.get(), &a));
        return a;
    }
    std::size_t bytes() const noexcept { return guiding_snapshot_bytes(handle_.get()); }
    explicit Snapshot(GuidingSnapshot *p) : handle_(p) {}

private:
    std::unique_ptr<GuidingSnapshot, detail::FreeSnapshot> handle_;
};

inline Snapshot snapshot(const Glt &glt) {
    GuidingSnapshot *p = nullptr;
    check(guiding_glt_snapshot(glt.get(), &p));
    return Snapshot(p);
}

// The directional calls, the same for the SD-tree and the field: `Self`
// gives `get()`, `Ops` the C functions.
#define GUIDING_DIRECTION_CALLS(prefix)                                                               \
    DirectionSample sample_direction(const ShadingContext &ctx, float u0, float u1) const {           \
        const float u[2] = {u0, u1};                                                                  \
        DirectionSample s;                                                                            \
        check(prefix##_sample_direction(get(), &ctx, u, &s));                                        \
        return s;                                                                                     \
    }                                                                                                 \
    float direction_pdf(const ShadingContext &ctx, const Vec3 &direction) const {                     \
        float p = 0;                                                                                  \
        check(prefix##_direction_pdf(get(), &ctx, direction.data(), &p));                             \
        return p;                                                                                     \
    }                                                                                                 \
    float bsdf_fraction(const ShadingContext &ctx) const {                                            \
        float a = 0;                                                                                  \
        check(prefix##_bsdf_fraction(get(), &ctx, &a));                                               \
        return a;                                                                                     \
    }                                                                                                 \
    float mixture_pdf(const ShadingContext &ctx, const Vec3 &direction, float bsdf_pdf) const {       \
        float p = 0;                                                                                  \
        check(prefix##_mixture_pdf(get(), &ctx, direction.data(), bsdf_pdf, &p));                     \
        return p;                                                                                     \
    }                                                                                                 \
    RecordOutcome record_radiance(const ShadingContext &ctx, const Vec3 &direction, float radiance,   \
                                  float pdf) const {                                                  \
        RecordOutcome o = GUIDING_RECORD_OUTCOME_RECORDED;                                            \
        check(prefix##_record_radiance(get(), &ctx, direction.data(), radiance, pdf, &o));            \
        return o;                                                                                     \
    }                                                                                                 \
    RecordOutcome record_fraction(const ShadingContext &ctx, float bsdf_pdf, float guiding_pdf,       \
                                  float contribution) const {                                         \
        RecordOutcome o = GUIDING_RECORD_OUTCOME_RECORDED;                                            \
        check(prefix##_record_fraction(get(), &ctx, bsdf_pdf, guiding_pdf, contribution, &o));        \
        return o;                                                                                     \
    }                                                                                                 \
    RefineOutcome refine() {                                                                          \
        RefineOutcome r;                                                                              \
        check(prefix##_refine(get(), &r));                                                            \
        return r;                                                                                     \
    }                                                                                                 \
    void clear_records() { check(prefix##_clear_records(get())); }                                    \
    std::vector<std::uint8_t> save() const {                                                          \
        GuidingBuffer b;                                                                              \
        check(prefix##_save(get(), &b));                                                              \
        return detail::take(b);                                                                       \
    }                                                                                                 \
    std::uint32_t iteration() const noexcept { return prefix##_iteration(get()); }                    \
    std::uint64_t dropped_records() const noexcept { return prefix##_dropped_records(get()); }

// Practical Path Guiding's SD-tree: learned directions per region.
class SdTree {
public:
    SdTree(const Vec3 &lower, const Vec3 &upper, const SdTreeConfig &config = default_sd_tree_config()) {
        GuidingSdTree *p = nullptr;
        check(guiding_sd_tree_new(lower.data(), upper.data(), &config, &p));
        handle_.reset(p);
    }
    static SdTree load(span<const std::uint8_t> bytes) {
        GuidingSdTree *p = nullptr;
        check(guiding_sd_tree_load(bytes.data(), bytes.size(), &p));
        return SdTree(p);
    }
    void merge(const SdTree &other) { check(guiding_sd_tree_merge(get(), other.get())); }
    GUIDING_DIRECTION_CALLS(guiding_sd_tree)
    GuidingSdTree *get() const noexcept { return handle_.get(); }

private:
    explicit SdTree(GuidingSdTree *p) : handle_(p) {}
    std::unique_ptr<GuidingSdTree, detail::FreeSdTree> handle_;
};

// The SD-tree and the GLT in one spatial tree: the light choice and the
// directions from one lookup.
class Field {
public:
    Field(const LightTree &tree, const Vec3 &lower, const Vec3 &upper,
          const FieldConfig &config = default_field_config()) {
        GuidingField *p = nullptr;
        check(guiding_field_new(tree.get(), lower.data(), upper.data(), &config, &p));
        handle_.reset(p);
    }
    static Field load(const LightTree &tree, span<const std::uint8_t> bytes) {
        GuidingField *p = nullptr;
        check(guiding_field_load(tree.get(), bytes.data(), bytes.size(), &p));
        return Field(p);
    }
    LightSample sample(const ShadingContext &ctx, float u) const {
        LightSample s;
        check(guiding_field_sample(get(), &ctx, u, &s));
        return s;
    }
    float pmf(const ShadingContext &ctx, std::uint32_t light) const {
        float p = 0;
        check(guiding_field_pmf(get(), &ctx, light, &p));
        return p;
    }
    RecordOutcome record_light(const ShadingContext &ctx, std::uint32_t light, float value) const {
        RecordOutcome o = GUIDING_RECORD_OUTCOME_RECORDED;
        check(guiding_field_record_light(get(), &ctx, light, value, &o));
        return o;
    }
    void merge(const Field &other) { check(guiding_field_merge(get(), other.get())); }
    Snapshot snapshot() const {
        GuidingSnapshot *p = nullptr;
        check(guiding_field_snapshot(get(), &p));
        return Snapshot(p);
    }
    std::uint32_t light_count() const noexcept { return guiding_field_light_count(get()); }
    GUIDING_DIRECTION_CALLS(guiding_field)
    GuidingField *get() const noexcept { return handle_.get(); }

private:
    explicit Field(GuidingField *p) : handle_(p) {}
    std::unique_ptr<GuidingField, detail::FreeField> handle_;
};

#undef GUIDING_DIRECTION_CALLS

}  // namespace guiding

#endif  // GUIDING_HPP
