// The C++ wrapper (guiding.hpp) driving a renderer's next-event
// estimation, with rays cast as a C++ renderer casts them (its own small
// ray caster: two rooms of ceiling lamps with a wall and a door between).
// Four threads sample and record into one guide at once; between passes
// it refines. Then, at shading points in both rooms: the NEE estimate
// with the GLT's choice agrees with brute force (every lamp integrated),
// sample == pmf, the batched calls agree, errors arrive as exceptions.
// Run by tests/c_api.rs (under valgrind when installed).

#include "guiding.hpp"

#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

namespace {

int failures = 0;

#define CHECK(cond, ...)                                                \
    do {                                                                \
        if (!(cond)) {                                                  \
            std::fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, #cond); \
            std::fprintf(stderr, __VA_ARGS__);                          \
            std::fprintf(stderr, "\n");                                 \
            failures++;                                                 \
        }                                                               \
    } while (0)

struct Rng {
    std::uint64_t s;
    float next() {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        return float(s >> 40) * (1.0f / 16777216.0f) * 0.99999994f;
    }
};

// Two 10 x 10 rooms side by side (x in [0, 10] and [10, 20]), 4 high; the
// wall at x = 10 has a door at z in [4, 6] below y = 2.5.
struct Lamp {
    guiding::Vec3 corner, edge_u, edge_v;
    float power, area, radiance;
};

struct Scene {
    std::vector<Lamp> lamps;

    bool occluded(const guiding::Vec3 &a, const guiding::Vec3 &b) const {
        if ((a[0] < 10.0f) == (b[0] < 10.0f)) return false;
        float t = (10.0f - a[0]) / (b[0] - a[0]);
        float y = a[1] + t * (b[1] - a[1]), z = a[2] + t * (b[2] - a[2]);
        bool through_door = z > 4.0f && z < 6.0f && y < 2.5f;
        return !through_door;
    }

    // What lamp `l` gives at `x` (normal +y) through its point at (s, t):
    // radiance * V * cos_x * cos_l / d^2 (per unit area of the lamp), and
    // the crate's record without the cosine at x.
    void contribution(const guiding::Vec3 &x, std::uint32_t l, float s, float t, float &with_cos,
                      float &without_cos) const {
        const Lamp &m = lamps[l];
        guiding::Vec3 y = {m.corner[0] + s * m.edge_u[0] + t * m.edge_v[0], m.corner[1],
                           m.corner[2] + s * m.edge_u[2] + t * m.edge_v[2]};
        float dx = y[0] - x[0], dy = y[1] - x[1], dz = y[2] - x[2];
        float d2 = dx * dx + dy * dy + dz * dz, d = std::sqrt(d2);
        float cos_x = dy / d, cos_l = dy / d;  // the lamp faces down, the floor up
        if (cos_x <= 0 || occluded(x, y)) {
            with_cos = without_cos = 0;
            return;
        }
        without_cos = m.radiance * cos_l / d2;
        with_cos = without_cos * cos_x;
    }

    // Irradiance at `x` from every lamp, by a 24 x 24 midpoint rule on each.
    double brute_force(const guiding::Vec3 &x) const {
        const int n = 24;
        double e = 0;
        for (std::uint32_t l = 0; l < lamps.size(); l++) {
            double sum = 0;
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    float w, wo;
                    contribution(x, l, (i + 0.5f) / n, (j + 0.5f) / n, w, wo);
                    sum += w;
                }
            e += sum / (n * n) * lamps[l].area;
        }
        return e;
    }
};

guiding::ShadingContext floor_point(float x, float z) { return guiding::shading_context({x, 0, z}, {0, 1, 0}); }

// One NEE sample at `ctx` with the GLT: the estimate, and the record made.
float nee(const Scene &scene, const guiding::Glt &glt, const guiding::ShadingContext &ctx, Rng &rng, bool record) {
    guiding::LightSample s = glt.sample(ctx, rng.next());
    if (s.light == GUIDING_NO_LIGHT) return 0;
    const guiding::Vec3 x = {ctx.position[0], ctx.position[1], ctx.position[2]};
    float with_cos, without_cos;
    scene.contribution(x, s.light, rng.next(), rng.next(), with_cos, without_cos);
    float area = scene.lamps[s.light].area;
    if (record) glt.record_light(ctx, s.light, without_cos * area / s.pmf);
    return with_cos * area / s.pmf;
}

}  // namespace

int main() {
    Scene scene;
    guiding::Emitters emitters;
    for (int room = 0; room < 2; room++)
        for (int i = 0; i < 8; i++)
            for (int j = 0; j < 8; j++) {
                Lamp m;
                m.corner = {10.0f * room + 0.6f + 1.2f * i, 3.9f, 0.6f + 1.2f * j};
                m.edge_u = {0.3f, 0, 0};
                m.edge_v = {0, 0, 0.3f};
                m.power = (room == 0 ? 1.0f : 4.0f) * (1.0f + float((i * 8 + j) % 5));
                m.area = 0.09f;
                m.radiance = m.power / (3.14159265f * m.area);
                // edge_u x edge_v points to -y: the lamps face the floor.
                std::uint32_t index = emitters.add_quad(m.corner, m.edge_u, m.edge_v, m.power);
                CHECK(index == scene.lamps.size(), "index %u", index);
                scene.lamps.push_back(m);
            }
    guiding::LightTree tree(emitters);
    guiding::GltConfig config = guiding::default_glt_config();
    config.deterministic = true;
    guiding::Glt glt(tree, {0, 0, 0}, {20, 4, 10}, config);

    // Training: four passes, four render threads recording into one guide.
    for (int pass = 0; pass < 4; pass++) {
        std::vector<std::thread> threads;
        for (int t = 0; t < 4; t++)
            threads.emplace_back([&, t] {
                Rng rng{std::uint64_t(1000 * pass + t + 1)};
                for (int k = 0; k < 4000; k++) {
                    guiding::ShadingContext ctx = floor_point(20 * rng.next(), 10 * rng.next());
                    nee(scene, glt, ctx, rng, true);
                }
            });
        for (auto &t : threads) t.join();
        glt.refine();
    }
    CHECK(glt.iteration() == 4, "iteration %u", glt.iteration());
    CHECK(glt.dropped_records() == 0, "%llu dropped", (unsigned long long)glt.dropped_records());

    // Unbiased: the GLT's NEE mean against every lamp integrated, in the
    // dim room by the wall, in the bright room and in the door.
    const float points[3][2] = {{8.5f, 2.0f}, {15.0f, 5.0f}, {10.2f, 5.0f}};
    for (const auto &p : points) {
        guiding::ShadingContext ctx = floor_point(p[0], p[1]);
        double exact = scene.brute_force({p[0], 0, p[1]});
        Rng rng{77};
        const int n = 20000;
        double sum = 0, sum2 = 0;
        for (int k = 0; k < n; k++) {
            double e = nee(scene, glt, ctx, rng, false);
            sum += e;
            sum2 += e * e;
        }
        double mean = sum / n, err = std::sqrt((sum2 / n - mean * mean) / n);
        CHECK(std::fabs(mean - exact) < 4 * err + 2e-3 * exact, "at (%g, %g): NEE %g +- %g, brute force %g", p[0],
              p[1], mean, err, exact);
        std::printf("at (%g, %g): NEE %.5f +- %.5f, brute force %.5f\n", p[0], p[1], mean, err, exact);
    }

    // sample == pmf, pmfs sum to 1, and the batched calls agree.
    {
        Rng rng{5};
        std::vector<guiding::ShadingContext> cs;
        std::vector<float> us;
        for (int k = 0; k < 32; k++) {
            cs.push_back(floor_point(20 * rng.next(), 10 * rng.next()));
            us.push_back(rng.next());
        }
        std::vector<guiding::LightSample> out(cs.size());
        glt.sample(cs, us, out);
        std::vector<std::uint32_t> lights;
        for (std::size_t k = 0; k < cs.size(); k++) {
            guiding::LightSample one = glt.sample(cs[k], us[k]);
            CHECK(one.light == out[k].light && one.pmf == out[k].pmf, "batch %zu", k);
            CHECK(glt.pmf(cs[k], one.light) == one.pmf, "pmf %zu", k);
            double total = 0;
            for (std::uint32_t l = 0; l < glt.light_count(); l++) total += glt.pmf(cs[k], l);
            CHECK(std::fabs(total - 1) < 1e-5, "pmfs sum to %.8f", total);
            lights.push_back(one.light);
        }
        std::vector<float> pmfs(cs.size());
        glt.pmf(cs, lights, pmfs);
        for (std::size_t k = 0; k < cs.size(); k++) CHECK(pmfs[k] == out[k].pmf, "batch pmf %zu", k);
    }

    // Errors are exceptions with the status; the guide goes on.
    try {
        glt.sample(floor_point(1, 1), 1.0f);
        CHECK(false, "u = 1 was accepted");
    } catch (const guiding::Error &e) {
        CHECK(e.status() == GUIDING_STATUS_INVALID_ARGUMENT, "status %d", int(e.status()));
        CHECK(std::string(e.what()).find("u = 1") != std::string::npos, "message %s", e.what());
    }
    try {
        glt.record_light(floor_point(1, 1), 0, NAN);
        CHECK(false, "a NaN record was accepted");
    } catch (const guiding::Error &e) {
        CHECK(e.status() == GUIDING_STATUS_INVALID_ARGUMENT, "status %d", int(e.status()));
    }
    CHECK(glt.dropped_records() == 1, "the NaN was not counted");
    try {
        guiding::Glt::load(tree, std::vector<std::uint8_t>{1, 2, 3});
        CHECK(false, "garbage loaded");
    } catch (const guiding::Error &e) {
        CHECK(e.status() == GUIDING_STATUS_LOAD_FAILED, "status %d", int(e.status()));
    }

    // Save, load over a reloaded tree, merge: a farm of two in C++.
    guiding::LightTree tree2 = guiding::LightTree::load(tree.save());
    std::vector<std::uint8_t> bytes = glt.save();
    guiding::Glt a = guiding::Glt::load(tree2, bytes), b = guiding::Glt::load(tree2, bytes);
    guiding::Glt all = guiding::Glt::load(tree2, bytes);
    a.clear_records();
    b.clear_records();
    all.clear_records();
    Rng ra{31}, rb{32}, rall_a{31}, rall_b{32};
    for (int k = 0; k < 2000; k++) {
        guiding::ShadingContext ca = floor_point(20 * ra.next(), 10 * ra.next());
        nee(scene, a, ca, ra, true);
        guiding::ShadingContext cb = floor_point(20 * rb.next(), 10 * rb.next());
        nee(scene, b, cb, rb, true);
        guiding::ShadingContext c1 = floor_point(20 * rall_a.next(), 10 * rall_a.next());
        nee(scene, all, c1, rall_a, true);
        guiding::ShadingContext c2 = floor_point(20 * rall_b.next(), 10 * rall_b.next());
        nee(scene, all, c2, rall_b, true);
    }
    a.merge(b);
    a.refine();
    all.refine();
    CHECK(a.save() == all.save(), "the merged farm differs from one guide");

    // The field and the SD-tree through their classes: one lookup's light
    // and direction, each sample equal to its pmf or pdf.
    {
        guiding::Field field(tree, {0, 0, 0}, {20, 4, 10});
        Rng rng{9};
        for (int pass = 0; pass < 2; pass++) {
            for (int k = 0; k < 3000; k++) {
                guiding::ShadingContext ctx = floor_point(20 * rng.next(), 10 * rng.next());
                guiding::LightSample s = field.sample(ctx, rng.next());
                field.record_light(ctx, s.light, 1.0f / s.pmf);
                guiding::DirectionSample d = field.sample_direction(ctx, rng.next(), rng.next());
                field.record_radiance(ctx, {d.direction[0], d.direction[1], d.direction[2]}, d.direction[1] > 0 ? 1.0f : 0.0f, d.pdf);
            }
            field.refine();
        }
        guiding::ShadingContext ctx = floor_point(3, 3);
        guiding::LightSample s = field.sample(ctx, 0.4f);
        CHECK(field.pmf(ctx, s.light) == s.pmf, "field pmf");
        guiding::DirectionSample d = field.sample_direction(ctx, 0.3f, 0.6f);
        CHECK(field.direction_pdf(ctx, {d.direction[0], d.direction[1], d.direction[2]}) == d.pdf, "field pdf");
        CHECK(field.snapshot().bytes() > 0, "field snapshot");
        guiding::Field copy = guiding::Field::load(tree, field.save());
        CHECK(copy.sample(ctx, 0.4f).light == s.light, "loaded field");
        guiding::SdTree sd({0, 0, 0}, {20, 4, 10}, guiding::improved_sd_tree_config());
        guiding::DirectionSample e = sd.sample_direction(ctx, 0.5f, 0.5f);
        CHECK(sd.direction_pdf(ctx, {e.direction[0], e.direction[1], e.direction[2]}) == e.pdf, "sd pdf");
        CHECK(guiding::snapshot(glt).bytes() > 0, "glt snapshot");
    }

    if (failures) {
        std::fprintf(stderr, "%d checks failed\n", failures);
        return 1;
    }
    std::printf("nee_test: every check passed\n");
    return 0;
}
