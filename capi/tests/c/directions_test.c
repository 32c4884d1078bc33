/* The SD-tree's and the combined field's C API: learned directions whose
   sample equals their pdf, a pdf that integrates to 1, mass where the
   radiance came from, the field answering both the light choice and the
   directions at one point, save / load / merge, and bad input refused.
   Run by tests/c_api.rs (under valgrind when installed). */

#include "guiding.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

static uint64_t rng_state = 1;
static float next_float(void) {
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (float)(rng_state >> 40) * (1.0f / 16777216.0f);
}

static GuidingShadingContext at(float x, float z) {
    GuidingShadingContext c = {{x, 1.0f, z}, {0, 0, 0}, GUIDING_ALL_LIGHTS, GUIDING_ALL_LIGHTS};
    return c;
}

/* Radiance arriving along `d`: a bright lobe around +x, dim elsewhere. */
static float radiance(const float d[3]) {
    return d[0] > 0.8f ? 10.0f : 0.1f;
}

/* One training pass: directions from the guide (half of them uniform, as a
   BSDF would add), their radiance recorded with the mixture's pdf. */
static void train_sd(const GuidingSdTree *sd, int n, uint64_t seed) {
    rng_state = seed;
    for (int i = 0; i < n; i++) {
        GuidingShadingContext c = at(10 * next_float(), 10 * next_float());
        float u[2] = {next_float() * 0.999999f, next_float() * 0.999999f};
        GuidingDirectionSample s;
        OK(guiding_sd_tree_sample_direction(sd, &c, u, &s));
        float q = 0;
        OK(guiding_sd_tree_mixture_pdf(sd, &c, s.direction, 1.0f / (4.0f * 3.14159265f), &q));
        OK(guiding_sd_tree_record_radiance(sd, &c, s.direction, radiance(s.direction), q, NULL));
    }
}

static int same_sd(const GuidingSdTree *a, const GuidingSdTree *b) {
    GuidingBuffer x, y;
    OK(guiding_sd_tree_save(a, &x));
    OK(guiding_sd_tree_save(b, &y));
    int same = x.len == y.len && memcmp(x.data, y.data, x.len) == 0;
    guiding_buffer_free(&x);
    guiding_buffer_free(&y);
    return same;
}

int main(void) {
    const float lo[3] = {0, 0, 0}, hi[3] = {10, 2, 10};
    GuidingSdTreeConfig config;
    OK(guiding_sd_tree_config_default(&config));
    config.deterministic = true;
    GuidingSdTreeConfig bad = config;
    bad.rho = -1.0f;
    GuidingSdTree *refused = NULL;
    CHECK(guiding_sd_tree_new(lo, hi, &bad, &refused) == GUIDING_STATUS_INVALID_CONFIG, "rho -1");
    bad = config;
    bad.directional_filter = 9;
    CHECK(guiding_sd_tree_new(lo, hi, &bad, &refused) == GUIDING_STATUS_INVALID_CONFIG, "filter 9");
    CHECK(refused == NULL, "out written on failure");
    GuidingSdTreeConfig improved;
    OK(guiding_sd_tree_config_improved(&improved));
    CHECK(improved.spatial_threshold == 4000.0 && improved.learn_bsdf_fraction, "improved settings");

    GuidingSdTree *sd = NULL;
    OK(guiding_sd_tree_new(lo, hi, &config, &sd));
    for (int it = 0; it < 5; it++) {
        train_sd(sd, 20000, 10 + (uint64_t)it);
        OK(guiding_sd_tree_refine(sd, NULL));
    }
    CHECK(guiding_sd_tree_iteration(sd) == 5, "iteration %u", guiding_sd_tree_iteration(sd));
    CHECK(guiding_sd_tree_dropped_records(sd) == 0, "dropped");

    /* sample == pdf; the pdf integrates to 1; the lobe gets the mass. */
    GuidingShadingContext c = at(5, 5);
    rng_state = 99;
    int in_lobe = 0;
    const int n = 4000;
    double integral = 0;
    for (int i = 0; i < n; i++) {
        float u[2] = {next_float() * 0.999999f, next_float() * 0.999999f};
        GuidingDirectionSample s;
        OK(guiding_sd_tree_sample_direction(sd, &c, u, &s));
        float p = -1;
        OK(guiding_sd_tree_direction_pdf(sd, &c, s.direction, &p));
        CHECK(p == s.pdf && p > 0, "sampled pdf %.9g, pdf %.9g", s.pdf, p);
        float len = sqrtf(s.direction[0] * s.direction[0] + s.direction[1] * s.direction[1] + s.direction[2] * s.direction[2]);
        CHECK(fabsf(len - 1) < 1e-5f, "|direction| = %g", len);
        in_lobe += s.direction[0] > 0.8f;
    }
    /* The integral over the sphere, from uniform directions. */
    const int m = 20000;
    double square = 0;
    for (int i = 0; i < m; i++) {
        float z = 1 - 2 * next_float(), phi = 6.2831853f * next_float(), r = sqrtf(fmaxf(0, 1 - z * z));
        float d[3] = {r * cosf(phi), r * sinf(phi), z};
        float q;
        OK(guiding_sd_tree_direction_pdf(sd, &c, d, &q));
        integral += q * 4 * 3.14159265 / m;
        square += (q * 4 * 3.14159265) * (q * 4 * 3.14159265) / m;
    }
    double error = sqrt((square - integral * integral) / m);
    CHECK(fabs(integral - 1) < 4 * error, "the pdf integrates to %.4f +- %.4f", integral, error);
    CHECK(in_lobe > n / 2, "%d of %d samples in the lobe (uniform: %d)", in_lobe, n, n / 10);
    float a = 0;
    OK(guiding_sd_tree_bsdf_fraction(sd, &c, &a));
    CHECK(a == 0.5f, "bsdf fraction %g", a);

    /* Bad input. */
    const float zero[3] = {0, 0, 0}, x[3] = {1, 0, 0};
    float p;
    float bad_u[2] = {0.5f, 1.0f};
    GuidingDirectionSample s;
    CHECK(guiding_sd_tree_sample_direction(sd, &c, bad_u, &s) == GUIDING_STATUS_INVALID_ARGUMENT, "u 1");
    CHECK(guiding_sd_tree_sample_direction(sd, &c, NULL, &s) == GUIDING_STATUS_NULL_POINTER, "null u");
    CHECK(guiding_sd_tree_direction_pdf(sd, &c, zero, &p) == GUIDING_STATUS_INVALID_ARGUMENT, "zero direction");
    CHECK(guiding_sd_tree_mixture_pdf(sd, &c, x, -1.0f, &p) == GUIDING_STATUS_INVALID_ARGUMENT, "negative bsdf pdf");
    GuidingRecordOutcome o = GUIDING_RECORD_OUTCOME_RECORDED;
    CHECK(guiding_sd_tree_record_radiance(sd, &c, x, 1.0f, 0.0f, &o) == GUIDING_STATUS_INVALID_ARGUMENT, "pdf 0");
    CHECK(o == GUIDING_RECORD_OUTCOME_DROPPED, "outcome %d", (int)o);
    CHECK(guiding_sd_tree_dropped_records(sd) == 1, "not counted");
    OK(guiding_sd_tree_record_fraction(sd, &c, 0.1f, 0.2f, 1.0f, &o));
    CHECK(o == GUIDING_RECORD_OUTCOME_IGNORED, "a fraction record without a learned fraction: %d", (int)o);

    /* Save, load, and a farm of two. */
    GuidingBuffer bytes;
    OK(guiding_sd_tree_save(sd, &bytes));
    GuidingSdTree *one = NULL, *w1 = NULL, *w2 = NULL, *junk = NULL;
    OK(guiding_sd_tree_load(bytes.data, bytes.len, &one));
    OK(guiding_sd_tree_load(bytes.data, bytes.len, &w1));
    OK(guiding_sd_tree_load(bytes.data, bytes.len, &w2));
    CHECK(guiding_sd_tree_load(bytes.data, bytes.len - 1, &junk) == GUIDING_STATUS_LOAD_FAILED, "short bytes");
    guiding_buffer_free(&bytes);
    CHECK(same_sd(sd, one), "loaded differs");
    OK(guiding_sd_tree_clear_records(one));
    OK(guiding_sd_tree_clear_records(w1));
    OK(guiding_sd_tree_clear_records(w2));
    train_sd(one, 3000, 70);
    train_sd(one, 3000, 71);
    train_sd(w1, 3000, 70);
    train_sd(w2, 3000, 71);
    OK(guiding_sd_tree_merge(w1, w2));
    CHECK(guiding_sd_tree_merge(w1, w1) == GUIDING_STATUS_INVALID_ARGUMENT, "merge with itself");
    OK(guiding_sd_tree_refine(one, NULL));
    OK(guiding_sd_tree_refine(w1, NULL));
    CHECK(same_sd(one, w1), "the farm differs from one tree");
    guiding_sd_tree_free(one);
    guiding_sd_tree_free(w1);
    guiding_sd_tree_free(w2);
    guiding_sd_tree_free(sd);

    /* The field: both halves at one point. */
    GuidingEmitters *e = NULL;
    OK(guiding_emitters_new(&e));
    for (int i = 0; i < 50; i++) {
        const float pos[3] = {10.0f * (float)(i % 10) / 10, 1.9f, 10.0f * (float)(i / 10) / 5};
        OK(guiding_emitters_add_sphere(e, pos, 0.05f, 1.0f + (float)(i % 3), NULL));
    }
    GuidingLightTree *tree = NULL;
    OK(guiding_light_tree_build(e, GUIDING_HEURISTIC_SARH, &tree));
    guiding_emitters_free(e);
    GuidingFieldConfig fc;
    OK(guiding_field_config_default(&fc));
    fc.sd.deterministic = true;
    GuidingFieldConfig fbad = fc;
    fbad.cut.alpha = -3;
    GuidingField *field = NULL;
    CHECK(guiding_field_new(tree, lo, hi, &fbad, &field) == GUIDING_STATUS_INVALID_CONFIG, "alpha -3");
    OK(guiding_field_new(tree, lo, hi, &fc, &field));
    CHECK(guiding_field_light_count(field) == 50, "light count %u", guiding_field_light_count(field));
    for (int it = 0; it < 3; it++) {
        rng_state = 300 + (uint64_t)it;
        for (int i = 0; i < 10000; i++) {
            GuidingShadingContext fctx = at(10 * next_float(), 10 * next_float());
            GuidingLightSample ls;
            OK(guiding_field_sample(field, &fctx, next_float() * 0.999999f, &ls));
            OK(guiding_field_record_light(field, &fctx, ls.light, 1.0f / ls.pmf, NULL));
            float u[2] = {next_float() * 0.999999f, next_float() * 0.999999f};
            GuidingDirectionSample ds;
            OK(guiding_field_sample_direction(field, &fctx, u, &ds));
            OK(guiding_field_record_radiance(field, &fctx, ds.direction, radiance(ds.direction), ds.pdf, NULL));
        }
        OK(guiding_field_refine(field, NULL));
    }
    rng_state = 5;
    for (int i = 0; i < 50; i++) {
        GuidingShadingContext fctx = at(10 * next_float(), 10 * next_float());
        GuidingLightSample ls;
        OK(guiding_field_sample(field, &fctx, next_float() * 0.999999f, &ls));
        float lp;
        OK(guiding_field_pmf(field, &fctx, ls.light, &lp));
        CHECK(lp == ls.pmf, "field light pmf %g against %g", lp, ls.pmf);
        double sum = 0;
        for (uint32_t l = 0; l < 50; l++) {
            OK(guiding_field_pmf(field, &fctx, l, &lp));
            sum += lp;
        }
        CHECK(fabs(sum - 1) < 1e-5, "field pmfs sum to %.8f", sum);
        float u[2] = {next_float() * 0.999999f, next_float() * 0.999999f};
        GuidingDirectionSample ds;
        OK(guiding_field_sample_direction(field, &fctx, u, &ds));
        float dp;
        OK(guiding_field_direction_pdf(field, &fctx, ds.direction, &dp));
        CHECK(dp == ds.pdf, "field direction pdf %g against %g", dp, ds.pdf);
    }
    GuidingSnapshot *snap = NULL;
    OK(guiding_field_snapshot(field, &snap));
    GuidingSnapshotArrays arrays;
    OK(guiding_snapshot_arrays(snap, &arrays));
    CHECK(arrays.leaf_position.count == 50 && arrays.cells.count > 0, "field snapshot");
    guiding_snapshot_free(snap);
    GuidingBuffer fb;
    OK(guiding_field_save(field, &fb));
    GuidingField *field2 = NULL;
    OK(guiding_field_load(tree, fb.data, fb.len, &field2));
    guiding_buffer_free(&fb);
    GuidingShadingContext fctx = at(3, 3);
    GuidingLightSample l1, l2;
    OK(guiding_field_sample(field, &fctx, 0.3f, &l1));
    OK(guiding_field_sample(field2, &fctx, 0.3f, &l2));
    CHECK(l1.light == l2.light && l1.pmf == l2.pmf, "the loaded field chooses otherwise");
    CHECK(guiding_field_iteration(field2) == 3, "iteration %u", guiding_field_iteration(field2));
    guiding_field_free(field2);
    guiding_field_free(field);
    guiding_light_tree_free(tree);
    guiding_sd_tree_free(NULL);
    guiding_field_free(NULL);

    if (failures) {
        fprintf(stderr, "%d checks failed\n", failures);
        return 1;
    }
    printf("directions_test: every check passed\n");
    return 0;
}
