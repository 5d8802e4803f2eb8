/* Shared by the fuzz harnesses: read typed values from the input bytes, and check the
 * invariants every output must keep, so that a harness catches wrong answers, not only crashes. */
#ifndef VPDS_FUZZ_COMMON_H
#define VPDS_FUZZ_COMMON_H
#include "vpds.h"
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const uint8_t *p;
    size_t n;
} bytes_t;

static uint8_t take_u8(bytes_t *b)
{
    uint8_t v = 0;
    if (b->n) {
        v = *b->p++;
        b->n--;
    }
    return v;
}

static uint32_t take_u32(bytes_t *b)
{
    uint32_t v = 0;
    int i;
    for (i = 0; i < 4; i++) v = v << 8 | take_u8(b);
    return v;
}

/* A double in [lo, hi], or now and then a special value (NaN, inf, 0, negative, huge). */
static double take_double(bytes_t *b, double lo, double hi, int specials)
{
    uint8_t tag = take_u8(b);
    if (specials && tag >= 248) {
        static const double sp[8] = {0.0, -1.0, 1e300, -1e-300, 1e-300, 0.0, 0.0, 0.0};
        if (tag == 248) return NAN;
        if (tag == 249) return INFINITY;
        if (tag == 250) return -INFINITY;
        return sp[tag - 251];
    }
    return lo + (hi - lo) * (double)take_u32(b) / 4294967295.0;
}

#define FUZZ_ASSERT(cond, ...) do { if (!(cond)) { fprintf(stderr, "invariant broken: %s: ", #cond); \
    fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); abort(); } } while (0)

static double rule_f(vpds_rule rule, double rx, double ry)
{
    switch (rule) {
    case VPDS_RULE_PRIOR: return rx;
    case VPDS_RULE_CURRENT: return ry;
    case VPDS_RULE_BIGGER: return rx > ry ? rx : ry;
    default: return rx < ry ? rx : ry;
    }
}

/* Every status is one the API documents. */
static void check_status(vpds_status st)
{
    FUZZ_ASSERT(st >= VPDS_ERR_DOMAIN && st <= VPDS_STREAM_END, "status %d", (int)st);
    FUZZ_ASSERT(strncmp(vpds_status_string(st), "VPDS_", 5) == 0, "status %d has no name", (int)st);
}

/* Samples i and j < i do not conflict (Eq. 10, with the radii the library recorded and i's
 * scale). */
static void check_pair(const vpds_sampler *s, size_t i, size_t j, const double *lo,
                       const double *hi, vpds_rule rule, double inhibition, const int *periodic)
{
    int d = vpds_dim(s), k;
    const double *x = vpds_points(s), *r = vpds_radii(s), *t = vpds_scales(s);
    double d2 = 0, f = t[i] * inhibition * rule_f(rule, r[j], r[i]);
    for (k = 0; k < d; k++) {
        double e = fabs(x[i * d + k] - x[j * d + k]), P = hi[k] - lo[k];
        if (periodic && periodic[k] && e > 0.5 * P) e = P - e; /* toroidal */
        d2 += e * e;
    }
    /* a stream's samples keep off by t * (1 - VPDS_STREAM_TOLERANCE) */
    f *= 1 - VPDS_STREAM_TOLERANCE;
    FUZZ_ASSERT(d2 >= f * f, "sample %zu conflicts with %zu (%g < %g)", i, j, sqrt(d2), f);
}

/* Samples sorted by the binary exponent of r, then by the first coordinate. */
typedef struct {
    int cls;   /* frexp exponent of r */
    double x0; /* first coordinate */
    size_t i;
} sorted_sample;

static int by_class_then_x0(const void *a, const void *b)
{
    const sorted_sample *u = (const sorted_sample *)a, *v = (const sorted_sample *)b;
    if (u->cls != v->cls) return u->cls < v->cls ? -1 : 1;
    return u->x0 < v->x0 ? -1 : u->x0 > v->x0;
}

/* Sample i against every earlier sample of one radius class (sorted entries [a, b)) whose first
 * coordinate lies within w of i's: those beyond cannot conflict. */
static void check_class(const vpds_sampler *s, size_t i, const sorted_sample *e, size_t a,
                        size_t b, double w, const double *lo, const double *hi, vpds_rule rule,
                        double inhibition, const int *periodic)
{
    double x = vpds_points(s)[i * (size_t)vpds_dim(s)];
    size_t lo_i = a, hi_i = b, q;
    while (lo_i < hi_i) { /* the first entry with x0 > x - w */
        size_t mid = lo_i + (hi_i - lo_i) / 2;
        if (e[mid].x0 > x - w) hi_i = mid; else lo_i = mid + 1;
    }
    for (q = lo_i; q < b && e[q].x0 < x + w; q++)
        if (e[q].i < i) check_pair(s, i, e[q].i, lo, hi, rule, inhibition, periodic);
}

/* Samples `from` on: finite, r > 0, inside the box unless fixed, and none conflicts with one
 * before it (check_pair); a harness that checked the earlier ones passes from = how many it
 * checked. Every rule's f is at most max(r_i, r_j), so a conflict needs |x0_i - x0_j| < t_i *
 * inhibition * max(r_i, r_j): on an open first axis the samples are grouped by the binary
 * exponent of r (within a group r varies by at most 2x) and sorted by x0 in each, and a new
 * sample is checked against those of each group within twice that bound along x0 (the group's
 * largest r for r_j), not against all: the fuzzer's slowest inputs hold thousands. */
static void check_samples_since(const vpds_sampler *s, size_t from, const double *lo,
                                const double *hi, vpds_rule rule, double inhibition,
                                const int *periodic)
{
    size_t n = vpds_count(s), i, j, a, b;
    int d = vpds_dim(s), k;
    const double *x = vpds_points(s), *r = vpds_radii(s), *t = vpds_scales(s);
    const uint8_t *fl = vpds_flags(s);
    sorted_sample *e;
    if (rule == VPDS_RULE_DEFAULT) rule = VPDS_RULE_SMALLER;
    for (i = from; i < n; i++) {
        FUZZ_ASSERT(isfinite(r[i]) && r[i] > 0, "r[%zu] = %g", i, r[i]);
        for (k = 0; k < d; k++) {
            FUZZ_ASSERT(isfinite(x[i * d + k]), "x[%zu] not finite", i);
            if (!(fl[i] & VPDS_FLAG_FIXED))
                FUZZ_ASSERT(x[i * d + k] >= lo[k] && x[i * d + k] <= hi[k], "x[%zu] outside the box", i);
        }
        if (fl[i] & VPDS_FLAG_FIXED) FUZZ_ASSERT(isinf(t[i]), "fixed point %zu has t = %g", i, t[i]);
        else FUZZ_ASSERT(t[i] >= 0, "t[%zu] = %g", i, t[i]); /* inf: a stream's first sample */
    }
    if (n <= 64 || (periodic && periodic[0])) { /* every pair */
        for (i = from; i < n; i++)
            for (j = 0; j < i && !(fl[i] & VPDS_FLAG_FIXED); j++)
                check_pair(s, i, j, lo, hi, rule, inhibition, periodic);
        return;
    }
    e = (sorted_sample *)malloc(n * sizeof *e);
    FUZZ_ASSERT(e != NULL, "out of memory checking %zu samples", n);
    for (i = 0; i < n; i++) {
        frexp(r[i], &e[i].cls);
        e[i].x0 = x[i * d];
        e[i].i = i;
    }
    qsort(e, n, sizeof *e, by_class_then_x0);
    for (a = 0; a < n; a = b) { /* one class [a, b) at a time */
        double r_max = 0;
        for (b = a; b < n && e[b].cls == e[a].cls; b++) r_max = r[e[b].i] > r_max ? r[e[b].i] : r_max;
        for (i = from; i < n; i++) {
            double w = 2 * t[i] * inhibition * (r[i] > r_max ? r[i] : r_max); /* 2: round-off */
            if (fl[i] & VPDS_FLAG_FIXED) continue;
            if (isnan(w)) w = INFINITY;
            check_class(s, i, e, a, b, w, lo, hi, rule, inhibition, periodic);
        }
    }
    free(e);
}

/* All the samples so far, as check_samples_since. */
static void check_samples_on(const vpds_sampler *s, const double *lo, const double *hi,
                             vpds_rule rule, double inhibition, const int *periodic)
{
    check_samples_since(s, 0, lo, hi, rule, inhibition, periodic);
}

/* The samples a harness checked, kept to show that later calls leave them as they were (they
 * only append), so that each call's check covers its new samples alone. */
typedef struct {
    double *copy; /* count records of dim + 3 doubles: coordinates, r, t, flags */
    size_t count;
} checked_t;

/* Sample i as a record of checked_t. */
static void sample_record(const vpds_sampler *s, size_t i, double *rec)
{
    size_t d = (size_t)vpds_dim(s);
    memcpy(rec, vpds_points(s) + i * d, d * sizeof(double));
    rec[d] = vpds_radii(s)[i];
    rec[d + 1] = vpds_scales(s)[i];
    rec[d + 2] = (double)vpds_flags(s)[i];
}

/* After a call: the kept samples unchanged (bit for bit), the new ones checked, then all of
 * them kept. */
static void check_new_samples(checked_t *c, const vpds_sampler *s, const double *lo,
                              const double *hi, vpds_rule rule, double inhibition,
                              const int *periodic)
{
    size_t n = vpds_count(s), i, w = (size_t)vpds_dim(s) + 3;
    double now[VPDS_MAX_DIM + 3], *grown;
    FUZZ_ASSERT(n >= c->count, "the count fell from %zu to %zu", c->count, n);
    for (i = 0; i < c->count; i++) {
        sample_record(s, i, now);
        FUZZ_ASSERT(memcmp(now, c->copy + i * w, w * sizeof(double)) == 0,
                    "sample %zu changed after it was checked", i);
    }
    check_samples_since(s, c->count, lo, hi, rule, inhibition, periodic);
    grown = (double *)realloc(c->copy, (n ? n : 1) * w * sizeof(double));
    FUZZ_ASSERT(grown != NULL, "out of memory keeping %zu samples", n);
    c->copy = grown;
    for (i = c->count; i < n; i++) sample_record(s, i, grown + i * w);
    c->count = n;
}

static void check_samples(const vpds_sampler *s, const double *lo, const double *hi,
                          vpds_rule rule, double inhibition)
{
    check_samples_on(s, lo, hi, rule, inhibition, NULL);
}

/* After a completed run: random probes in the box are covered at scale * f (for a constant
 * radius, where the harness knows r at any point), toroidally on periodic axes. */
static void check_covered_on(const vpds_sampler *s, const double *lo, const double *hi,
                             double radius, double scale, const int *periodic, bytes_t *b)
{
    size_t n = vpds_count(s), i, p;
    int d = vpds_dim(s), k;
    const double *x = vpds_points(s), *r = vpds_radii(s);
    for (p = 0; p < 64; p++) {
        double y[VPDS_MAX_DIM], best = INFINITY;
        for (k = 0; k < d; k++) y[k] = lo[k] + (hi[k] - lo[k]) * (double)((take_u8(b) * 131 + p * 37) % 257) / 256.0;
        for (i = 0; i < n; i++) {
            double d2 = 0, f = scale * (r[i] < radius ? r[i] : radius);
            for (k = 0; k < d; k++) {
                double e = fabs(y[k] - x[i * d + k]), P = hi[k] - lo[k];
                if (periodic && periodic[k] && e > 0.5 * P) e = P - e;
                d2 += e * e;
            }
            if (sqrt(d2) - f < best) best = sqrt(d2) - f;
        }
        FUZZ_ASSERT(n > 0 && best <= 1e-9 * radius, "probe %zu uncovered by %g", p, best);
    }
}

static void check_covered(const vpds_sampler *s, const double *lo, const double *hi, double radius,
                          double scale, bytes_t *b)
{
    check_covered_on(s, lo, hi, radius, scale, NULL, b);
}
#endif
