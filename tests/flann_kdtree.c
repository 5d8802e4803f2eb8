/* The kd-tree against FLANN's exact search (a single kd-tree with unlimited checks): radius
 * queries and the answer of each proximity primitive (PiX, XiP, BiX, XiB and the bigger/smaller
 * combinations), on random, clustered and degenerate inputs (duplicates, points on splitting
 * planes), in 1D to 6D. FLANN takes the radius as a float of the squared distance, so points
 * within a relative 1e-5 of a query's boundary are left out of the comparison. */
#include "check.h"
#include "kdtree.h"
#include "ogrid.h"
#include "mem.h"
#include "rules.h"
#include <flann/flann.h>
#include <math.h>
#include <string.h>

#define NMAX 4000

static uint64_t state = 99;
static double unit(void)
{
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(state >> 11) * (1.0 / 9007199254740992.0);
}

typedef struct {
    flann_index_t index;
    struct FLANNParameters params;
    int *idx;
    double *dist;
} flann_ref;

/* FLANN: indices within radius of q; returns count (every point at most, so nothing is cut) */
static int flann_within(flann_ref *f, int n, double *q, double radius)
{
    return flann_radius_search_double(f->index, q, f->idx, f->dist, n, (float)(radius * radius),
                                      &f->params);
}

static int in_band(double d2, double radius)
{
    return fabs(d2 - radius * radius) <= 1e-5 * radius * radius + 1e-300;
}

static double dist2(const double *a, const double *b, int d)
{
    double s = 0;
    int k;
    for (k = 0; k < d; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return s;
}

static int compared = 0, skipped = 0;

/* The samples near the box [lo, hi] (r_bound rp): the kd-tree's, the hashed octave grid's and
 * the one with arrays' are the same. mark: n bytes of scratch. */
static void check_near_box(const char *name, const vpdsi_kdtree *t, const vpdsi_ogrid *og,
                           const vpdsi_ogrid *ogd, const vpdsi_kd_samples *s, int n,
                           const double *lo, const double *hi, double rp, char *mark)
{
    vpdsi_mem m;
    int32_t *out = NULL;
    size_t cnt[3] = {0, 0, 0}, cap = 0, a;
    int which;
    vpdsi_mem_init(&m, NULL);
    memset(mark, 0, (size_t)n);
    for (which = 0; which < 3; which++) {
        size_t first = which ? cnt[which - 1] : 0;
        cnt[which] = first;
        if (which == 0)
            CHECK(vpdsi_kd_near_box(t, s, lo, hi, rp, 1.0, 0, (size_t)n + 1, &m, &out, &cnt[0], &cap) == 0);
        else
            CHECK(vpdsi_ogrid_near_box(which == 1 ? og : ogd, s, lo, hi, rp, 1.0, &m, &out, &cnt[which],
                                       &cap) == 0);
        for (a = first; a < cnt[which]; a++) mark[out[a]] |= (char)(1 << which);
        cnt[which] -= first;
    }
    for (a = 0; a < (size_t)n; a++)
        if (mark[a] != 0 && mark[a] != 7) break;
    CHECK_MSG(a == (size_t)n && cnt[0] == cnt[1] && cnt[0] == cnt[2], "%s: the samples near a box "
              "differ (kd-tree %zu, octave grid %zu, with arrays %zu; sample %zu: %d)", name, cnt[0],
              cnt[1], cnt[2], a, a < (size_t)n ? mark[a] : 0);
    vpdsi_mem_free(&m, out, cap * sizeof *out);
}

/* Samples and queries past the box (a tile's neighbours, round-off): the octave grid clamps
 * them into its first and last cells, and still finds them, hashed or in arrays. */
static void check_past_box(void)
{
    static const double box_lo[2] = {0, 0}, box_hi[2] = {1, 1};
    double x[8] = {3.0, 0.5, -2.0, 0.5, 0.5, 0.5, 0.5, 1.7}, r[4] = {0.1, 0.1, 0.1, 0.1};
    uint8_t flags[4] = {0, 0, 0, 0};
    vpdsi_kd_samples s;
    vpdsi_mem m;
    int dense, i;
    s.x = x;
    s.r = r;
    s.flags = flags;
    vpdsi_mem_init(&m, NULL);
    for (dense = 0; dense < 2; dense++) {
        vpdsi_ogrid g;
        CHECK(vpdsi_ogrid_setup(&g, 2, box_lo, box_hi, 0.1, 0.1, dense ? 1e6 : 0) == 0);
        CHECK(g.n_hashed == (dense ? 0 : 1));
        CHECK(vpdsi_ogrid_reserve(&g, &m, 4, 4) == 0);
        for (i = 0; i < 4; i++) vpdsi_ogrid_insert(&g, &s, i);
        for (i = 0; i < 4; i++) {
            double q[2] = {x[2 * i] + 0.05, x[2 * i + 1]}, lo[2], hi[2];
            int32_t w, *out = NULL;
            size_t cnt = 0, cap = 0;
            int rule = VPDS_RULE_SMALLER;
            CHECK_MSG(vpdsi_ogrid_conflict(&g, &s, q, 0.1, rule, 1.0, -1.0, &w) == i,
                      "a query by sample %d at (%g, %g) missed it (arrays: %d)", i, x[2 * i], x[2 * i + 1], dense);
            lo[0] = hi[0] = q[0];
            lo[1] = hi[1] = q[1];
            CHECK(vpdsi_ogrid_near_box(&g, &s, lo, hi, 0.1, 1.0, &m, &out, &cnt, &cap) == 0);
            CHECK_MSG(cnt == 1 && out[0] == i, "the samples near (%g, %g): %zu (arrays: %d)", q[0], q[1],
                      cnt, dense);
            vpdsi_mem_free(&m, out, cap * sizeof *out);
        }
        vpdsi_ogrid_release(&g, &m);
    }
    CHECK(m.held == 0);
}

/* The samples within f(r(x), rp) of the box [lo, hi] by the octave grid (hashed: which 0, with
 * arrays: 1; vpdsi_ogrid_near_rule, the sweep's list for the cells under an ancestor) are FLANN's
 * (ids[0..nf), a superset) at that distance, and hold every sample its gather lists for the
 * box and for any box inside it (split or not): the sweep filters them for each cell. mark: n
 * zero bytes of scratch, left zero. */
static void check_near_rule(const char *name, const vpdsi_ogrid *og, const vpdsi_kd_samples *s, int dim,
                            const int *ids, int nf, const double *lo, const double *hi, double rp, int rule,
                            char *mark, int which)
{
    vpdsi_mem m;
    int32_t *out = NULL;
    size_t cnt = 0, cap = 0, a;
    double ilo[3], ihi[3];
    int j, k, split;
    vpdsi_mem_init(&m, NULL);
    for (k = 0; k < dim; k++) { /* a box inside: its lower three quarters */
        ilo[k] = lo[k];
        ihi[k] = lo[k] + 0.75 * (hi[k] - lo[k]);
    }
    for (split = 0; split < 4; split++) /* the box and the one inside, split or not */
        CHECK(vpdsi_ogrid_gather(og, s, split < 2 ? lo : ilo, split < 2 ? hi : ihi, rp, rule, 1.0, split % 2,
                                 &m, &out, &cnt, &cap) == 0);
    for (a = 0; a < cnt; a++) mark[out[a]] = 8;
    cnt = 0;
    CHECK(vpdsi_ogrid_near_rule(og, s, lo, hi, rp, rule, 1.0, &m, &out, &cnt, &cap) == 0);
    for (a = 0; a < cnt; a++) mark[out[a]] |= 16;
    for (j = 0; j < nf; j++) {
        const double *x = s->x + (size_t)ids[j] * (size_t)dim;
        double fr = vpdsi_rule_f((vpds_rule)rule, s->r[ids[j]], rp), g2 = 0;
        int listed = (mark[ids[j]] & 16) != 0;
        for (k = 0; k < dim; k++) {
            double e = x[k] < lo[k] ? lo[k] - x[k] : x[k] > hi[k] ? x[k] - hi[k] : 0;
            g2 += e * e;
        }
        if (!in_band(g2, fr))
            CHECK_MSG(listed == (g2 <= fr * fr), "%s: octave grid (arrays: %d) near_rule (rule %d) %s "
                      "sample %d at %g of the box, reach %g", name, which, rule, listed ? "lists" : "misses",
                      ids[j], sqrt(g2), fr);
        CHECK_MSG(listed || !(mark[ids[j]] & 8), "%s: octave grid (arrays: %d) near_rule (rule %d) misses "
                  "sample %d that the gather lists", name, which, rule, ids[j]);
    }
    for (a = 0; a < cnt; a++) { /* and each it lists is near (FLANN's radius is a float) */
        const double *x = s->x + (size_t)out[a] * (size_t)dim;
        double fr = vpdsi_rule_f((vpds_rule)rule, s->r[out[a]], rp), g2 = 0;
        for (k = 0; k < dim; k++) {
            double e = x[k] < lo[k] ? lo[k] - x[k] : x[k] > hi[k] ? x[k] - hi[k] : 0;
            g2 += e * e;
        }
        CHECK_MSG(g2 <= fr * fr * (1 + 1e-6), "%s: near_rule lists sample %d at %g of the box, reach %g", name,
                  (int)out[a], sqrt(g2), fr);
    }
    for (j = 0; j < nf; j++) mark[ids[j]] = 0;
    for (a = 0; a < cnt; a++) mark[out[a]] = 0;
    vpdsi_mem_free(&m, out, cap * sizeof *out);
    CHECK(m.held == 0);
}

static void check_set(const char *name, int dim, int n, double *x, double *r)
{
    vpdsi_mem m;
    vpdsi_kdtree t;
    vpdsi_kd_samples s;
    flann_ref f;
    float speedup;
    uint8_t flags[NMAX];
    int32_t *out = NULL, i;
    size_t cnt = 0, cap = 0;
    int q, k, rule;
    double rmax = 0;
    char *mark = (char *)calloc((size_t)n, 1);
    vpdsi_ogrid og, ogd; /* hashed cells; levels from the least radius, the coarsest in arrays */
    int use_og = dim <= 3;
    double rmin = INFINITY;
    int32_t *out2 = NULL;
    size_t cnt2 = 0, cap2 = 0;
    double box_lo[6] = {0}, box_hi[6] = {1, 1, 1, 1, 1, 1};
    vpdsi_mem_init(&m, NULL);
    vpdsi_kd_init(&t, dim);
    memset(flags, 0, sizeof flags);
    s.x = x; s.r = r; s.flags = flags;
    CHECK(vpdsi_kd_reserve(&t, &m, (size_t)n, (size_t)n) == 0);
    for (i = 0; i < n; i++) {
        vpdsi_kd_insert(&t, &s, i);
        if (r[i] > rmax) rmax = r[i];
        if (r[i] < rmin) rmin = r[i];
    }
    /* the octave grid over the same samples (their box: [0, 1]^dim) */
    if (use_og) {
        CHECK(vpdsi_ogrid_setup(&og, dim, box_lo, box_hi, rmax, 0, 0) == 0);
        CHECK(vpdsi_ogrid_reserve(&og, &m, (size_t)n, (size_t)n) == 0);
        for (i = 0; i < n; i++) vpdsi_ogrid_insert(&og, &s, i);
        CHECK(vpdsi_ogrid_setup(&ogd, dim, box_lo, box_hi, rmax, rmin, 200000) == 0);
        CHECK(vpdsi_ogrid_reserve(&ogd, &m, (size_t)n, (size_t)n) == 0);
        for (i = 0; i < n; i++) vpdsi_ogrid_insert(&ogd, &s, i);
        CHECK_MSG(ogd.levels > ogd.n_hashed && ogd.levels <= og.levels, "%s: %d levels, %d of them in "
                  "arrays, against %d", name, ogd.levels, ogd.levels - ogd.n_hashed, og.levels);
    }
    f.params = DEFAULT_FLANN_PARAMETERS;
    f.params.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    f.params.checks = FLANN_CHECKS_UNLIMITED;
    f.params.log_level = FLANN_LOG_NONE;
    f.index = flann_build_index_double(x, n, dim, &speedup, &f.params);
    f.idx = (int *)malloc(sizeof(int) * (size_t)n);
    f.dist = (double *)malloc(sizeof(double) * (size_t)n);
    CHECK(f.index != NULL);
    for (q = 0; q < 300; q++) {
        double p[6], radius = (0.2 + unit()) * rmax * 2, rp = r[q % n];
        int nf, j, bad = 0;
        /* queries: random, on a data point, on a data point's coordinate planes */
        for (k = 0; k < dim; k++) {
            if (q % 3 == 0) p[k] = unit() * 1.2 - 0.1;
            else if (q % 3 == 1) p[k] = x[(q % n) * dim + k];
            else p[k] = x[((q * 7) % n) * dim + k] + (k % 2 ? 0 : 1e-3);
        }
        /* radius search */
        cnt = 0;
        CHECK(vpdsi_kd_radius(&t, &s, p, radius, &m, &out, &cnt, &cap) == 0);
        nf = flann_within(&f, n, p, radius);
        memset(mark, 0, (size_t)n);
        for (j = 0; j < (int)cnt; j++) mark[out[j]] |= 1;
        for (j = 0; j < nf; j++) mark[f.idx[j]] |= 2;
        for (i = 0; i < n; i++) {
            if (mark[i] == 0 || mark[i] == 3) { compared++; continue; }
            if (in_band(dist2(p, x + i * dim, dim), radius)) { skipped++; continue; }
            bad++;
        }
        CHECK_MSG(bad == 0, "%s: radius search differs from FLANN at %d points", name, bad);
        /* each rule's conflict primitive: any x with |p - x| < f(r(x), rp) */
        nf = flann_within(&f, n, p, rmax > rp ? rmax : rp);
        for (rule = VPDS_RULE_PRIOR; rule <= VPDS_RULE_SMALLER; rule++) {
            int32_t w, ours = vpdsi_kd_conflict(&t, &s, p, rp, rule, 1.0, -1.0, &w) >= 0, ref = 0,
                       ambiguous = 0;
            int32_t grid = use_og ? vpdsi_ogrid_conflict(&og, &s, p, rp, rule, 1.0, -1.0, &w) >= 0 : ours;
            int32_t dense = use_og ? vpdsi_ogrid_conflict(&ogd, &s, p, rp, rule, 1.0, -1.0, &w) >= 0 : ours;
            for (j = 0; j < nf; j++) {
                int id = f.idx[j];
                double fr = vpdsi_rule_f((vpds_rule)rule, r[id], rp), d2 = dist2(p, x + id * dim, dim);
                if (d2 < fr * fr) ref = 1;
                if (in_band(d2, fr)) ambiguous = 1;
            }
            if (ours != ref && !ambiguous)
                CHECK_MSG(0, "%s: conflict rule %d: ours %d, FLANN %d", name, rule, ours, ref);
            if (grid != ref && !ambiguous)
                CHECK_MSG(0, "%s: octave grid conflict rule %d: ours %d, FLANN %d", name, rule, grid, ref);
            CHECK_MSG(grid == ours, "%s: octave grid and kd-tree conflicts differ (rule %d)", name, rule);
            CHECK_MSG(dense == ours, "%s: the octave grid with arrays and the kd-tree's conflicts "
                      "differ (rule %d)", name, rule);
        }
        /* each rule's box coverage primitive on a box around p */
        {
            double lo[6], hi[6], side = rmax * (0.05 + 0.5 * unit()), half = 0, c[6];
            for (k = 0; k < dim; k++) {
                lo[k] = p[k] - side / 2;
                hi[k] = p[k] + side / 2;
                c[k] = p[k];
                half += side * side / 4;
            }
            half = sqrt(half);
            nf = flann_within(&f, n, c, (rmax > rp ? rmax : rp) + half);
            if (use_og) check_near_box(name, &t, &og, &ogd, &s, n, lo, hi, rp, mark);
            for (rule = VPDS_RULE_PRIOR; rule <= VPDS_RULE_SMALLER; rule++) {
                int ours, ref = 0, ambiguous = 0;
                cnt = 0;
                CHECK(vpdsi_kd_gather(&t, &s, lo, hi, rp, rule, 1.0, 0, &m, &out, &cnt, &cap) == 0);
                ours = vpdsi_kd_box_covered(&t, &s, out, cnt, lo, hi, rp, rule, 1.0);
                if (use_og) {
                    /* the grid gathers the same candidates, in another order */
                    int split;
                    for (split = 0; split < 2; split++) {
                        size_t a;
                        cnt = cnt2 = 0;
                        CHECK(vpdsi_kd_gather(&t, &s, lo, hi, rp, rule, 1.0, split, &m, &out, &cnt, &cap) == 0);
                        CHECK(vpdsi_ogrid_gather(&og, &s, lo, hi, rp, rule, 1.0, split, &m, &out2, &cnt2, &cap2) == 0);
                        memset(mark, 0, (size_t)n);
                        for (a = 0; a < cnt; a++) mark[out[a]] |= 1;
                        for (a = 0; a < cnt2; a++) mark[out2[a]] |= 2;
                        for (a = 0; a < (size_t)n; a++)
                            if (mark[a] == 1 || mark[a] == 2) break;
                        CHECK_MSG(a == (size_t)n && cnt == cnt2, "%s: octave grid gather (rule %d, "
                                  "split %d) differs from the kd-tree's: %zu against %zu", name, rule,
                                  split, cnt2, cnt);
                        /* its per-sample test (the sweep's shortcut for the last holder) names
                         * exactly the samples it gathers */
                        for (a = 0; a < (size_t)n; a++)
                            if (vpdsi_ogrid_gathers(&s, dim, (int32_t)a, lo, hi, rp, rule, 1.0, split) !=
                                ((mark[a] & 2) != 0))
                                break;
                        CHECK_MSG(a == (size_t)n, "%s: vpdsi_ogrid_gathers (rule %d, split %d) and "
                                  "the gather disagree on sample %zu", name, rule, split, a);
                        cnt2 = 0;
                        CHECK(vpdsi_ogrid_gather(&ogd, &s, lo, hi, rp, rule, 1.0, split, &m, &out2, &cnt2, &cap2) == 0);
                        for (a = 0; a < cnt2; a++) mark[out2[a]] |= 4;
                        for (a = 0; a < (size_t)n; a++)
                            if (((mark[a] & 2) != 0) != ((mark[a] & 4) != 0)) break;
                        CHECK_MSG(a == (size_t)n && cnt == cnt2, "%s: the octave grid with arrays "
                                  "gathers other samples (rule %d, split %d): %zu against %zu", name,
                                  rule, split, cnt2, cnt);
                    }
                    memset(mark, 0, (size_t)n);
                    check_near_rule(name, &og, &s, dim, f.idx, nf, lo, hi, rp, rule, mark, 0);
                    check_near_rule(name, &ogd, &s, dim, f.idx, nf, lo, hi, rp, rule, mark, 1);
                    cnt = 0;
                    CHECK(vpdsi_kd_gather(&t, &s, lo, hi, rp, rule, 1.0, 0, &m, &out, &cnt, &cap) == 0);
                }
                for (j = 0; j < nf; j++) {
                    int id = f.idx[j];
                    double fr = vpdsi_rule_f((vpds_rule)rule, r[id], rp);
                    double far2 = vpdsi_box_maxdist2(&t, x + id * dim, lo, hi);
                    if (far2 <= fr * fr) ref = 1;
                    if (in_band(far2, fr)) ambiguous = 1;
                }
                if (ours != ref && !ambiguous)
                    CHECK_MSG(0, "%s: box coverage rule %d: ours %d, FLANN %d", name, rule, ours, ref);
            }
        }
    }
    flann_free_index_double(f.index, &f.params);
    free(f.idx);
    free(f.dist);
    vpdsi_mem_free(&m, out, cap * sizeof *out);
    vpdsi_mem_free(&m, out2, cap2 * sizeof *out2);
    if (use_og) {
        vpdsi_ogrid_release(&og, &m);
        vpdsi_ogrid_release(&ogd, &m);
    }
    free(mark);
    vpdsi_kd_release(&t, &m);
    CHECK(m.held == 0);
}

int main(void)
{
    static double x[NMAX * 6], r[NMAX];
    int dims[] = {1, 2, 3, 6}, di, i, k;
    check_past_box();
    for (di = 0; di < 4; di++) {
        int d = dims[di], n = 3000;
        char name[64];
        /* random */
        for (i = 0; i < n * d; i++) x[i] = unit();
        for (i = 0; i < n; i++) r[i] = 0.01 + 0.1 * unit();
        snprintf(name, sizeof name, "random %dD", d);
        check_set(name, d, n, x, r);
        /* clustered: tight Gaussian-ish clusters */
        for (i = 0; i < n; i++) {
            int c = i % 7;
            for (k = 0; k < d; k++)
                x[i * d + k] = 0.1 + 0.12 * c + 0.01 * (unit() + unit() + unit() - 1.5);
        }
        snprintf(name, sizeof name, "clustered %dD", d);
        check_set(name, d, n, x, r);
        /* duplicates: 40 distinct points, each repeated */
        for (i = 0; i < n; i++)
            for (k = 0; k < d; k++) x[i * d + k] = (i < 40) ? unit() : x[(i % 40) * d + k];
        snprintf(name, sizeof name, "duplicates %dD", d);
        check_set(name, d, n, x, r);
        /* a lattice: many points share every coordinate, so they sit on splitting planes */
        for (i = 0; i < n; i++)
            for (k = 0; k < d; k++) x[i * d + k] = (double)((i / (k + 1)) % 5) / 4.0;
        snprintf(name, sizeof name, "lattice %dD", d);
        check_set(name, d, n, x, r);
        /* radii over three octaves of ten: every level of the octave grid in use */
        for (i = 0; i < n * d; i++) x[i] = unit();
        for (i = 0; i < n; i++) r[i] = 0.0002 * pow(1000.0, unit());
        snprintf(name, sizeof name, "multi-scale %dD", d);
        check_set(name, d, n, x, r);
        for (i = 0; i < n; i++) r[i] = 0.01 + 0.1 * unit();
    }
    printf("FLANN comparisons: %d points agreed, %d within float rounding of a boundary\n",
           compared, skipped);
    CHECK(compared > 1000000);
    CHECK_DONE();
}
