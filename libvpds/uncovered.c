/* Branch-and-bound over boxes of the region's bounding box: a box is dropped when it misses
 * the region, lies outside the domain or inside one sample's coverage disk; a box point inside
 * the region and the domain and outside every coverage disk is an uncovered witness; anything
 * else splits into 2^d. Boxes
 * live in coordinates around the anchor; on a periodic axis the kd-tree wraps them. */
#include "uncovered.h"
#include "rules.h"
#include "sampler.h"
#include "torus.h"
#include <math.h>
#include <string.h>

#define UNCOVERED_BUDGET 20000 /* boxes per question before answering "yes" conservatively */
#define UNCOVERED_DEPTH 40


double vpdsi_coverage_reach(const vpds_sampler *s, double r_hi)
{
    double scale = s->run.t * s->coverage, sl = scale * s->sizing.lipschitz;
    int uses_u = s->rule == VPDS_RULE_CURRENT || s->rule == VPDS_RULE_BIGGER;
    if (!uses_u) return scale * r_hi;
    return sl < 1 ? scale * r_hi / (1 - sl) : INFINITY;
}

vpds_status vpdsi_uncovered_index(vpds_sampler *s)
{
    const vpdsi_run *run = &s->run;
    int d = s->dim, k;
    size_t i, m = 0, nx;
    uint64_t c[VPDS_MAX_DIM];
    vpdsi_kd_samples v;
    s->u_ready = 0;
    for (i = 0; i < run->next.count; i++) m += s->next_u[i] != 0;
    if (vpdsi_mul_size(m + 1, (size_t)d, &nx) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->ux, &s->cap_ux, nx, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->ur, &s->cap_ur, m + 1, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->uf, &s->cap_uf, m + 1, 1)) {
        vpdsi_set_error(s, "out of memory indexing %zu uncovered cells", m);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    vpdsi_kd_clear(&s->utree);
    if (vpdsi_kd_reserve(&s->utree, &s->mem, m + 1, m + 1)) {
        vpdsi_set_error(s, "out of memory indexing %zu uncovered cells", m);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    s->u_half = 0;
    v.x = s->ux;
    v.r = s->ur;
    v.flags = s->uf;
    for (i = 0, m = 0; i < run->next.count; i++) {
        double half2, lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
        if (!s->next_u[i]) continue;
        vpdsi_cells_get(&run->next, i, d, c);
        half2 = 0.25 * vpdsi_cell_box(s, run->next.level, c, lo, hi);
        for (k = 0; k < d; k++) s->ux[m * (size_t)d + (size_t)k] = 0.5 * (lo[k] + hi[k]);
        if (sqrt(half2) > s->u_half) s->u_half = sqrt(half2);
        s->ur[m] = 1.0;
        s->uf[m] = 0;
        vpdsi_kd_insert(&s->utree, &v, (int32_t)m);
        m++;
    }
    s->u_ready = 1;
    return VPDS_OK;
}

double vpdsi_uncovered_nearest(const vpds_sampler *s, const double *p)
{
    vpdsi_kd_samples v;
    int32_t arg;
    if (!s->u_ready) return 0.0;
    v.x = s->ux;
    v.r = s->ur;
    v.flags = s->uf;
    return vpdsi_kd_min_ratio(&s->utree, &v, p, 0.0, 1.0, (int)VPDS_RULE_PRIOR, &arg);
}

vpds_status vpdsi_uncovered_in(vpds_sampler *s, const double *alo, const double *ahi,
                               double r_anchor, int *found)
{
    int d = s->dim, k;
    unsigned children = 1u << d, b;
    double scale = s->run.t * s->coverage, L = s->sizing.lipschitz, sl = scale * L;
    int point = memcmp(alo, ahi, (size_t)d * sizeof(double)) == 0;
    /* largest reach of the region: r(u) <= r_anchor + L |u - a| and |u - a| <= scale r(u) */
    double reach = vpdsi_coverage_reach(s, r_anchor);
    double centre[VPDS_MAX_DIM];
    size_t top = 0, boxes = 0, stride = 2 * (size_t)d + 1, need;
    vpdsi_kd_samples view;
    vpds_status st;
    *found = 0;
    if (!(sl < 1)) {
        *found = 1;
        return VPDS_OK;
    }
    if (vpdsi_mul_size((size_t)UNCOVERED_DEPTH * children + 1, stride, &need) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->bb_stack, &s->cap_bb_stack, need, sizeof(double))) {
        vpdsi_set_error(s, "out of memory for the two-radii coverage search");
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if ((st = vpdsi_sync_tree(s)) != VPDS_OK) return st;
    for (k = 0; k < d; k++) {
        double *bx = s->bb_stack;
        double lo = alo[k] - reach, hi = ahi[k] + reach;
        centre[k] = 0.5 * (alo[k] + ahi[k]);
        if (s->period[k] == 0) { /* uncovered points lie in the box */
            if (lo < s->lo[k]) lo = s->lo[k];
            if (hi > s->hi[k]) hi = s->hi[k];
        }
        bx[k] = lo;
        bx[d + k] = hi;
        bx[2 * d] = 0;
    }
    top = 1;
    view = vpdsi_samples_view(s);
    while (top > 0) {
        double *bx = s->bb_stack + --top * stride, lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
        double p[VPDS_MAX_DIM], gap2 = 0, diag2 = 0, rp, diag, r_lo, r_hi;
        int depth = (int)bx[2 * d], in_region;
        int32_t w;
        memcpy(lo, bx, (size_t)d * sizeof(double));
        memcpy(hi, bx + d, (size_t)d * sizeof(double));
        if (++boxes > UNCOVERED_BUDGET) {
            *found = 1;
            return VPDS_OK;
        }
        for (k = 0; k < d; k++) {
            /* nearest point of the box to the anchor's centre, and the box-anchor gap */
            double g;
            p[k] = centre[k] < lo[k] ? lo[k] : centre[k] > hi[k] ? hi[k] : centre[k];
            g = alo[k] > hi[k] ? alo[k] - hi[k] : lo[k] > ahi[k] ? lo[k] - ahi[k] : 0;
            gap2 += g * g;
            diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        }
        if (gap2 > reach * reach) continue; /* misses the region */
        if (s->u_ready || s->domain) {
            double c2[VPDS_MAX_DIM], phi;
            for (k = 0; k < d; k++) c2[k] = 0.5 * (lo[k] + hi[k]);
            /* no cell that may hold an uncovered point meets the box */
            if (s->u_ready && vpdsi_uncovered_nearest(s, c2) > 0.5 * sqrt(diag2) + s->u_half) continue;
            /* the box lies outside the domain: nothing there needs covering */
            if (s->domain) {
                if ((st = vpdsi_domain_at(s, c2, &phi)) != VPDS_OK) return st;
                if (phi > 0.5 * sqrt(diag2)) continue;
            }
        }
        if ((st = vpdsi_radius_at(s, p, &rp)) != VPDS_OK) return st;
        if (point) {
            double f = scale * vpdsi_rule_f(s->rule, r_anchor, rp), d2 = 0;
            for (k = 0; k < d; k++) d2 += (p[k] - alo[k]) * (p[k] - alo[k]);
            in_region = d2 <= f * f;
        } else {
            double d2 = 0;
            for (k = 0; k < d; k++) {
                double g = p[k] < alo[k] ? alo[k] - p[k] : p[k] > ahi[k] ? p[k] - ahi[k] : 0;
                d2 += g * g;
            }
            in_region = d2 <= reach * reach;
        }
        if (in_region &&
            vpdsi_kd_conflict(&s->tree, &view, p, rp, (int)s->rule, scale, -1.0, &w) == -1) {
            /* p is uncovered: no sample within t*coverage*f of it; a witness if in the domain */
            double phi = 0;
            if (s->domain && (st = vpdsi_domain_at(s, p, &phi)) != VPDS_OK) return st;
            if (phi <= 0) {
                *found = 1;
                return VPDS_OK;
            }
        }
        diag = sqrt(diag2);
        r_lo = rp - L * diag;
        r_hi = rp + L * diag;
        s->n_cand2 = 0;
        if (vpdsi_kd_gather(&s->tree, &view, lo, hi, r_hi, (int)s->rule, scale, 0, &s->mem,
                            &s->cand2, &s->n_cand2, &s->cap_cand2)) {
            vpdsi_set_error(s, "out of memory gathering the samples near a box");
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        if (r_lo > 0 && vpdsi_kd_box_covered(&s->tree, &view, s->cand2, s->n_cand2, lo, hi, r_lo,
                                             (int)s->rule, scale))
            continue;
        if (depth >= UNCOVERED_DEPTH || !(diag > 1e-12 * reach)) {
            *found = 1; /* unresolved at the precision: count it as uncovered */
            return VPDS_OK;
        }
        for (b = 0; b < children; b++) {
            double *cb = s->bb_stack + top++ * stride;
            for (k = 0; k < d; k++) {
                double mid = 0.5 * (lo[k] + hi[k]);
                cb[k] = (b >> k) & 1u ? mid : lo[k];
                cb[d + k] = (b >> k) & 1u ? hi[k] : mid;
            }
            cb[2 * d] = depth + 1;
        }
    }
    return VPDS_OK;
}
