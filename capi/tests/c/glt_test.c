/* The C API as a C renderer uses it: lights, a light tree, a GLT trained
   for a few iterations, and its promises checked from C: sample == pmf
   exactly, pmfs sum to 1, save and load give the same choices, a merged
   farm equals one guide recording everything, and every bad input is a
   status code with a message, never a crash. Run by tests/c_api.rs. */

#include "guiding.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* A small deterministic generator (the test's, not the crate's). */
static uint64_t rng_state = 0x853c49e6748fea9bULL;
static float next_float(void) {
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (float)(rng_state >> 40) * (1.0f / 16777216.0f);
}

enum { GRID = 12, LIGHTS = GRID * GRID + 2 };
static float positions[LIGHTS][3];

static GuidingShadingContext point_on_floor(void) {
    GuidingShadingContext ctx;
    ctx.position[0] = 10.0f * next_float();
    ctx.position[1] = 0.0f;
    ctx.position[2] = 10.0f * next_float();
    ctx.normal[0] = 0.0f;
    ctx.normal[1] = 1.0f;
    ctx.normal[2] = 0.0f;
    ctx.light_sets = GUIDING_ALL_LIGHTS;
    ctx.unbounded_lights = GUIDING_ALL_LIGHTS;
    return ctx;
}

/* What NEE would have found: the unoccluded inverse-square falloff, with a
   wall at x = 5 hiding every light on the other side. */
static float contribution(const GuidingShadingContext *ctx, uint32_t light, float pmf) {
    const float *p = positions[light];
    float dx = p[0] - ctx->position[0], dy = p[1] - ctx->position[1], dz = p[2] - ctx->position[2];
    if ((p[0] < 5.0f) != (ctx->position[0] < 5.0f)) return 0.0f;
    return 1.0f / ((dx * dx + dy * dy + dz * dz + 0.1f) * pmf);
}

static void train(const GuidingGlt *glt, int paths, uint64_t seed) {
    rng_state = seed;
    for (int i = 0; i < paths; i++) {
        GuidingShadingContext ctx = point_on_floor();
        GuidingLightSample s;
        OK(guiding_glt_sample(glt, &ctx, next_float() * 0.999999f, &s));
        if (s.light == GUIDING_NO_LIGHT) continue;
        GuidingRecordOutcome outcome;
        OK(guiding_glt_record_light(glt, &ctx, s.light, contribution(&ctx, s.light, s.pmf), &outcome));
    }
}

static GuidingGlt *new_glt(const GuidingLightTree *tree, const GuidingGltConfig *config) {
    const float lo[3] = {0, 0, 0}, hi[3] = {10, 4, 10};
    GuidingGlt *glt = NULL;
    OK(guiding_glt_new(tree, lo, hi, config, &glt));
    return glt;
}

static int same_bytes(const GuidingGlt *a, const GuidingGlt *b) {
    GuidingBuffer x, y;
    OK(guiding_glt_save(a, &x));
    OK(guiding_glt_save(b, &y));
    int same = x.len == y.len && memcmp(x.data, y.data, x.len) == 0;
    OK(guiding_buffer_free(&x));
    OK(guiding_buffer_free(&y));
    return same;
}

int main(void) {
    GuidingEmitters *emitters = NULL;
    OK(guiding_emitters_new(&emitters));
    for (int i = 0; i < GRID * GRID; i++) {
        const float corner[3] = {10.0f * (float)(i % GRID) / GRID, 3.0f, 10.0f * (float)(i / GRID) / GRID};
        const float eu[3] = {0.2f, 0, 0}, ev[3] = {0, 0, 0.2f};
        uint32_t index = 0;
        /* Facing down, to the floor: edge_u x edge_v points to -y. */
        OK(guiding_emitters_add_quad(emitters, corner, eu, ev, 1.0f + (float)(i % 7), false, &index));
        CHECK(index == (uint32_t)i, "index %u", index);
        memcpy(positions[i], corner, sizeof corner);
    }
    const float sun_spot[3] = {2, 3.5f, 2}, down[3] = {0, -1, 0}, ball[3] = {8, 2, 8};
    OK(guiding_emitters_add_spot(emitters, sun_spot, down, 0.9f, 0.7f, 20.0f, NULL));
    OK(guiding_emitters_add_sphere(emitters, ball, 0.3f, 5.0f, NULL));
    memcpy(positions[GRID * GRID], sun_spot, sizeof sun_spot);
    memcpy(positions[GRID * GRID + 1], ball, sizeof ball);
    CHECK(guiding_emitters_count(emitters) == LIGHTS, "%zu emitters", guiding_emitters_count(emitters));

    /* Bad emitters are refused, and the list stays as it was. */
    const float nan3[3] = {NAN, 0, 0};
    CHECK(guiding_emitters_add_point(emitters, nan3, 1.0f, NULL) == GUIDING_STATUS_INVALID_ARGUMENT, "NaN position");
    CHECK(strlen(guiding_last_error()) > 0, "no message");
    CHECK(guiding_emitters_add_point(emitters, ball, -1.0f, NULL) == GUIDING_STATUS_INVALID_ARGUMENT, "negative power");
    CHECK(guiding_emitters_add_point(emitters, NULL, 1.0f, NULL) == GUIDING_STATUS_NULL_POINTER, "null position");
    CHECK(guiding_emitters_add_point(NULL, ball, 1.0f, NULL) == GUIDING_STATUS_NULL_POINTER, "null list");
    CHECK(guiding_emitters_add_spot(emitters, ball, down, 2.0f, 0.5f, 1.0f, NULL) == GUIDING_STATUS_INVALID_ARGUMENT, "cosine 2");
    CHECK(guiding_emitters_count(emitters) == LIGHTS, "the list changed");

    GuidingLightTree *tree = NULL;
    CHECK(guiding_light_tree_build(emitters, 99, &tree) == GUIDING_STATUS_INVALID_ARGUMENT, "heuristic 99");
    OK(guiding_light_tree_build(emitters, GUIDING_HEURISTIC_SARH, &tree));
    CHECK(guiding_light_tree_emitter_count(tree) == LIGHTS, "tree of %u", guiding_light_tree_emitter_count(tree));
    GuidingEmitters *none = NULL;
    OK(guiding_emitters_new(&none));
    /* No lights at all: a valid scene, where nothing can be sampled. */
    GuidingLightTree *empty = NULL;
    OK(guiding_light_tree_build(none, GUIDING_HEURISTIC_SARH, &empty));
    CHECK(guiding_light_tree_emitter_count(empty) == 0, "empty tree");
    {
        const float lo0[3] = {0, 0, 0}, hi0[3] = {1, 1, 1};
        GuidingGlt *dark = NULL;
        OK(guiding_glt_new(empty, lo0, hi0, NULL, &dark));
        GuidingShadingContext c = point_on_floor();
        GuidingLightSample s0 = {0, 1.0f};
        OK(guiding_glt_sample(dark, &c, 0.5f, &s0));
        CHECK(s0.light == GUIDING_NO_LIGHT && s0.pmf == 0.0f, "sampled %u in the dark", s0.light);
        float p0;
        CHECK(guiding_glt_pmf(dark, &c, 0, &p0) == GUIDING_STATUS_INVALID_ARGUMENT, "light 0 of none");
        OK(guiding_glt_refine(dark, NULL));
        guiding_glt_free(dark);
    }
    guiding_light_tree_free(empty);
    guiding_emitters_free(none);
    guiding_emitters_free(emitters);

    /* Configuration: the defaults, and out-of-range values refused. */
    GuidingGltConfig config;
    OK(guiding_glt_config_default(&config));
    config.deterministic = true;
    GuidingGltConfig bad = config;
    bad.cut.sigma = -1.0;
    const float lo[3] = {0, 0, 0}, hi[3] = {10, 4, 10};
    GuidingGlt *refused = NULL;
    CHECK(guiding_glt_new(tree, lo, hi, &bad, &refused) == GUIDING_STATUS_INVALID_CONFIG, "sigma -1");
    bad = config;
    bad.light_filter = 7;
    CHECK(guiding_glt_new(tree, lo, hi, &bad, &refused) == GUIDING_STATUS_INVALID_CONFIG, "filter 7");
    const float nan_corner[3] = {0, NAN, 0};
    CHECK(guiding_glt_new(tree, nan_corner, hi, &config, &refused) == GUIDING_STATUS_INVALID_ARGUMENT, "NaN bounds");
    CHECK(refused == NULL, "out written on failure");

    /* Training: four iterations. */
    GuidingGlt *glt = new_glt(tree, &config);
    for (int it = 0; it < 4; it++) {
        train(glt, 20000, 100 + (uint64_t)it);
        GuidingRefineOutcome r;
        OK(guiding_glt_refine(glt, &r));
    }
    CHECK(guiding_glt_iteration(glt) == 4, "iteration %u", guiding_glt_iteration(glt));
    CHECK(guiding_glt_light_count(glt) == LIGHTS, "light count");

    /* sample == pmf exactly, and the pmfs sum to 1. */
    rng_state = 7;
    for (int i = 0; i < 200; i++) {
        GuidingShadingContext ctx = point_on_floor();
        GuidingLightSample s;
        OK(guiding_glt_sample(glt, &ctx, next_float() * 0.999999f, &s));
        float p = -1.0f;
        OK(guiding_glt_pmf(glt, &ctx, s.light, &p));
        CHECK(p == s.pmf && p > 0.0f, "sample pmf %.9g, pmf %.9g", s.pmf, p);
        double sum = 0.0;
        for (uint32_t l = 0; l < LIGHTS; l++) {
            OK(guiding_glt_pmf(glt, &ctx, l, &p));
            CHECK(p >= 0.0f && isfinite(p), "pmf %g", p);
            sum += p;
        }
        CHECK(fabs(sum - 1.0) < 1e-5, "pmfs sum to %.9f", sum);
    }

    /* The batched calls answer what the single ones do; a bad element is
       refused before anything is written. */
    {
        enum { N = 64 };
        GuidingShadingContext cs[N];
        float us[N], pmfs[N];
        uint32_t ls[N];
        GuidingLightSample out[N];
        rng_state = 21;
        for (int i = 0; i < N; i++) {
            cs[i] = point_on_floor();
            us[i] = next_float() * 0.999999f;
        }
        OK(guiding_glt_sample_batch(glt, cs, us, N, out));
        for (int i = 0; i < N; i++) {
            GuidingLightSample one;
            OK(guiding_glt_sample(glt, &cs[i], us[i], &one));
            CHECK(one.light == out[i].light && one.pmf == out[i].pmf, "batch %d differs", i);
            ls[i] = out[i].light;
        }
        OK(guiding_glt_pmf_batch(glt, cs, ls, N, pmfs));
        for (int i = 0; i < N; i++) CHECK(pmfs[i] == out[i].pmf, "batch pmf %d: %g against %g", i, pmfs[i], out[i].pmf);
        us[N - 1] = NAN;
        out[0].light = 12345;
        CHECK(guiding_glt_sample_batch(glt, cs, us, N, out) == GUIDING_STATUS_INVALID_ARGUMENT, "NaN in a batch");
        CHECK(strstr(guiding_last_error(), "u[63]") != NULL, "message %s", guiding_last_error());
        CHECK(out[0].light == 12345, "out written before the batch was checked");
        ls[5] = LIGHTS;
        CHECK(guiding_glt_pmf_batch(glt, cs, ls, N, pmfs) == GUIDING_STATUS_INVALID_ARGUMENT, "light out of range in a batch");
        OK(guiding_glt_sample_batch(glt, NULL, NULL, 0, NULL)); /* an empty batch */
    }

    /* The learned choice sees the wall: from x < 5, lights beyond it get
       less than their unguided share. */
    {
        GuidingShadingContext ctx = point_on_floor();
        ctx.position[0] = 1.0f;
        ctx.position[2] = 5.0f;
        double beyond = 0.0;
        for (uint32_t l = 0; l < GRID * GRID; l++) {
            float p;
            OK(guiding_glt_pmf(glt, &ctx, l, &p));
            if (positions[l][0] >= 5.0f) beyond += p;
        }
        CHECK(beyond < 0.2, "%.3f of the choice behind the wall", beyond);
    }

    /* Bad queries: status codes, no crash, nothing learned from them. */
    GuidingShadingContext ctx = point_on_floor();
    GuidingLightSample s;
    float p;
    CHECK(guiding_glt_sample(glt, &ctx, NAN, &s) == GUIDING_STATUS_INVALID_ARGUMENT, "u NaN");
    CHECK(guiding_glt_sample(glt, &ctx, 1.0f, &s) == GUIDING_STATUS_INVALID_ARGUMENT, "u 1");
    CHECK(guiding_glt_sample(glt, NULL, 0.5f, &s) == GUIDING_STATUS_NULL_POINTER, "null ctx");
    CHECK(guiding_glt_sample(NULL, &ctx, 0.5f, &s) == GUIDING_STATUS_NULL_POINTER, "null glt");
    CHECK(guiding_glt_sample(glt, &ctx, 0.5f, NULL) == GUIDING_STATUS_NULL_POINTER, "null out");
    CHECK(guiding_glt_pmf(glt, &ctx, LIGHTS, &p) == GUIDING_STATUS_INVALID_ARGUMENT, "light out of range");
    GuidingShadingContext far = ctx;
    far.position[1] = INFINITY;
    CHECK(guiding_glt_sample(glt, &far, 0.5f, &s) == GUIDING_STATUS_INVALID_ARGUMENT, "infinite position");
    far = ctx;
    far.position[0] = 1e30f;
    OK(guiding_glt_sample(glt, &far, 0.5f, &s)); /* far outside: clamped onto the box */
    CHECK(s.light != GUIDING_NO_LIGHT && s.pmf > 0.0f, "far point");
    uint64_t dropped = guiding_glt_dropped_records(glt);
    GuidingRecordOutcome outcome = GUIDING_RECORD_OUTCOME_RECORDED;
    CHECK(guiding_glt_record_light(glt, &ctx, 0, NAN, &outcome) == GUIDING_STATUS_INVALID_ARGUMENT, "NaN value");
    CHECK(outcome == GUIDING_RECORD_OUTCOME_DROPPED, "outcome %d", (int)outcome);
    CHECK(guiding_glt_dropped_records(glt) == dropped + 1, "not counted");
    OK(guiding_glt_record_light(glt, &ctx, 0, 0.0f, &outcome));
    CHECK(outcome == GUIDING_RECORD_OUTCOME_ZERO, "outcome %d", (int)outcome);

    /* The GPU snapshot: plain arrays, one per buffer, their sizes adding
       up; one leaf position per emitter. */
    {
        GuidingSnapshot *snap = NULL;
        OK(guiding_glt_snapshot(glt, &snap));
        GuidingSnapshotArrays a;
        OK(guiding_snapshot_arrays(snap, &a));
        size_t total = a.header.bytes + a.spatial.bytes + a.cells.bytes + a.cut_nodes.bytes + a.fractions.bytes +
                       a.visibility.bytes + a.tree.bytes + a.first_right.bytes + a.bounds.bytes + a.leaf_position.bytes;
        CHECK(total == guiding_snapshot_bytes(snap) && total > 0, "%zu bytes against %zu", total, guiding_snapshot_bytes(snap));
        CHECK(a.header.count == 1 && a.cells.count > 1 && a.spatial.count >= a.cells.count, "cells %zu, nodes %zu", a.cells.count, a.spatial.count);
        CHECK(a.leaf_position.count == LIGHTS && a.leaf_position.bytes == 4 * LIGHTS, "leaf positions %zu", a.leaf_position.count);
        CHECK(a.cells.data != NULL && a.header.data != NULL, "null arrays");
        guiding_snapshot_free(snap);
        CHECK(guiding_glt_snapshot(glt, NULL) == GUIDING_STATUS_NULL_POINTER, "null out");
        guiding_snapshot_free(NULL);
    }

    /* Save and load: the same choices, bit for bit. */
    GuidingBuffer saved;
    OK(guiding_glt_save(glt, &saved));
    GuidingGlt *loaded = NULL;
    OK(guiding_glt_load(tree, saved.data, saved.len, &loaded));
    rng_state = 11;
    for (int i = 0; i < 100; i++) {
        GuidingShadingContext c = point_on_floor();
        float u = next_float() * 0.999999f;
        GuidingLightSample a, b;
        OK(guiding_glt_sample(glt, &c, u, &a));
        OK(guiding_glt_sample(loaded, &c, u, &b));
        CHECK(a.light == b.light && a.pmf == b.pmf, "loaded chose %u (%g), saved %u (%g)", b.light, b.pmf, a.light, a.pmf);
    }
    GuidingGlt *garbage = NULL;
    CHECK(guiding_glt_load(tree, saved.data, saved.len / 2, &garbage) == GUIDING_STATUS_LOAD_FAILED, "half the bytes");
    CHECK(guiding_glt_load(tree, NULL, 10, &garbage) == GUIDING_STATUS_NULL_POINTER, "null data");
    CHECK(garbage == NULL, "out written on failure");

    /* The light tree survives a save and load too. */
    GuidingBuffer tree_bytes;
    OK(guiding_light_tree_save(tree, &tree_bytes));
    GuidingLightTree *tree2 = NULL;
    OK(guiding_light_tree_load(tree_bytes.data, tree_bytes.len, &tree2));
    CHECK(guiding_light_tree_emitter_count(tree2) == LIGHTS, "reloaded tree");
    GuidingGlt *over_loaded_tree = NULL;
    OK(guiding_glt_load(tree2, saved.data, saved.len, &over_loaded_tree));
    CHECK(same_bytes(over_loaded_tree, glt), "a guide over the reloaded tree differs");
    OK(guiding_buffer_free(&tree_bytes));
    OK(guiding_buffer_free(&saved));
    CHECK(saved.data == NULL && saved.len == 0, "buffer not emptied");
    OK(guiding_buffer_free(&saved)); /* twice is harmless */

    /* A farm of two: copies of one guide record halves; merged, they equal
       one guide recording both halves (deterministic accumulation). */
    OK(guiding_glt_save(glt, &saved));
    GuidingGlt *one = NULL, *w1 = NULL, *w2 = NULL;
    OK(guiding_glt_load(tree, saved.data, saved.len, &one));
    OK(guiding_glt_load(tree, saved.data, saved.len, &w1));
    OK(guiding_glt_load(tree, saved.data, saved.len, &w2));
    OK(guiding_buffer_free(&saved));
    OK(guiding_glt_clear_records(one));
    OK(guiding_glt_clear_records(w1));
    OK(guiding_glt_clear_records(w2));
    train(one, 5000, 500);
    train(one, 5000, 501);
    train(w1, 5000, 500);
    train(w2, 5000, 501);
    OK(guiding_glt_merge(w1, w2));
    CHECK(guiding_glt_merge(w1, w1) == GUIDING_STATUS_INVALID_ARGUMENT, "merge with itself");
    GuidingGlt *other = new_glt(tree, &config);
    CHECK(guiding_glt_merge(w1, other) == GUIDING_STATUS_INCOMPATIBLE, "merge of strangers");
    OK(guiding_glt_refine(one, NULL));
    OK(guiding_glt_refine(w1, NULL));
    CHECK(same_bytes(one, w1), "the farm's guide differs from one guide's");

    guiding_glt_free(other);
    guiding_glt_free(one);
    guiding_glt_free(w1);
    guiding_glt_free(w2);
    guiding_glt_free(over_loaded_tree);
    guiding_glt_free(loaded);
    /* The tree handle may go before the guides over it. */
    guiding_light_tree_free(tree2);
    guiding_light_tree_free(tree);
    train(glt, 100, 9);
    guiding_glt_free(glt);
    guiding_glt_free(NULL);
    guiding_light_tree_free(NULL);
    guiding_emitters_free(NULL);

    if (failures) {
        fprintf(stderr, "%d checks failed\n", failures);
        return 1;
    }
    printf("glt_test: every check passed\n");
    return 0;
}
