/* Algorithm 1 (Section 3.1): darts thrown into a flat hyper-octree of active cells, then a
 * coverage sweep that splits every active cell into 2^d children and keeps the uncovered ones.
 *
 * Bias-free (Eq. 4): a dart picks an active cell uniformly (all cells of a level have the same
 * size) and a point uniformly in it; it becomes a sample iff it conflicts with no sample. The
 * active cells always contain every uncovered point, so accepted darts are uniform over the free
 * region. Work is cut into chunks; between chunks the state is complete, so a pause, an error
 * or an exhausted budget can resume to exactly the points of an uninterrupted run. */
#include "sampler.h"
#include "rules.h"
#include "torus.h"
#include "uncovered.h"
#include <math.h>
#include <string.h>

#ifndef DARTS_PER_CELL
#define DARTS_PER_CELL 0.5  /* A of Algorithm 1 */
#endif
#define CHUNK 256           /* darts or cells between checks of the budget */
#define PRECISION_BITS 44   /* cells stop splitting at 2^-44 of the coordinates' magnitude */

void vpdsi_mps_reset(vpds_sampler *s, double t)
{
    s->run.phase = VPDSI_IDLE;
    s->run.t = t;
    s->stats.t = t;
}

void vpdsi_mps_release(vpds_sampler *s)
{
    vpdsi_cells_release(&s->run.cur, &s->mem);
    vpdsi_cells_release(&s->run.next, &s->mem);
    if (s->grid_mode) {
        /* done at this scale: keep the samples, drop the accelerator (rebuilt on the next run) */
        vpdsi_bgrid_release(&s->grid, &s->mem);
        s->grid_mode = 0;
    }
}

#ifndef DARTS_PER_BASE_CELL
#define DARTS_PER_BASE_CELL 1.5 /* level 0 darts are the cheapest: no cell to read */
#endif
static uint64_t darts_for(uint64_t cells, unsigned level)
{
    double n = ceil((level ? DARTS_PER_CELL : DARTS_PER_BASE_CELL) * (double)cells);
    return n < 1 ? 1 : (uint64_t)n;
}

/* The background grid serves a uniform radius in low dimension; the kd-tree everything else.
 * (vpdsi_bgrid_setup releases the grid of an earlier scale; the kd-tree path releases it below.) */
static vpds_status choose_index(vpds_sampler *s)
{
    vpdsi_run *run = &s->run;
    double reach = run->t * s->inhibition * s->sizing.radius;
    size_t i;
    s->grid_mode = 0;
    if (s->sizing.kind == VPDSI_SIZING_CONSTANT && s->n_fixed == 0 && s->dim <= 3 &&
        !s->two_radii && !s->any_periodic && !s->stream.active &&
        vpdsi_bgrid_setup(&s->grid, &s->mem, s->dim, run->n0, s->lo, run->side0, reach) == 0 &&
        vpdsi_mem_reserve(&s->mem, (void **)&s->cand, &s->cap_cand, s->grid.n_stencil + 1,
                          sizeof(int32_t)) == 0) {
        s->grid_mode = 1;
        for (i = 0; i < s->n; i++) s->grid.cell[vpdsi_bgrid_locate(&s->grid, s->x + i * (size_t)s->dim)] = (int32_t)i;
        return VPDS_OK;
    }
    vpdsi_bgrid_release(&s->grid, &s->mem);
    return vpdsi_sync_tree(s);
}

/* Base grid for the current scale: cells of diagonal t*coverage*r_max, so that in the uniform
 * case a sample covers its whole cell. */
static vpds_status setup(vpds_sampler *s)
{
    vpdsi_run *run = &s->run;
    vpds_status st;
    int d = s->dim, k;
    double target = run->t * s->coverage * s->sizing.rmax / sqrt((double)d) * (1 - 1e-9);
    uint64_t total = 1;
    unsigned max_level = 62;
    for (k = 0; k < d; k++) {
        double ext = s->hi[k] - s->lo[k], cells = ceil(ext / target), mag, min_side;
        if (s->period[k] > 0 && !(ext > 2 * run->t * s->coverage * s->sizing.rmax)) {
            /* a disk would meet its own image across the wrap */
            vpdsi_set_error(s, "periodic axis %d: side %g is not above 2 * t * coverage * r_max ="
                            " %g (t = %g)", k, ext, 2 * run->t * s->coverage * s->sizing.rmax,
                            run->t);
            return VPDS_ERR_INVALID_ARGUMENT;
        }
        unsigned lev;
        if (!(cells <= 1099511627776.0)) { /* 2^40 per axis */
            vpdsi_set_error(s, "scale t = %g: axis %d of extent %g needs %g base cells of side %g;"
                            " the cell count overflows", run->t, k, ext, cells, target);
            return VPDS_ERR_OVERFLOW;
        }
        run->n0[k] = cells < 1 ? 1 : (uint64_t)cells;
        run->side0[k] = ext / (double)run->n0[k];
        if (total > (UINT64_C(1) << 40) / run->n0[k]) {
            /* no machine holds a sampling that fine: refuse rather than exhaust memory */
            vpdsi_set_error(s, "scale t = %g: the base grid has more than 2^40 cells (radius too"
                            " small for the box); the cell count overflows", run->t);
            return VPDS_ERR_OVERFLOW;
        }
        total *= run->n0[k];
        mag = fabs(s->lo[k]) > fabs(s->hi[k]) ? fabs(s->lo[k]) : fabs(s->hi[k]);
        if (ext > mag) mag = ext;
        min_side = ldexp(mag, -PRECISION_BITS);
        lev = 0;
        while (lev < 62 && ldexp(run->side0[k], -(int)(lev + 1)) >= min_side) lev++;
        if (lev + vpdsi_bit_length(run->n0[k]) > 63) lev = 63 - vpdsi_bit_length(run->n0[k]);
        if (lev < max_level) max_level = lev;
    }
    run->base_count = total;
    run->max_level = max_level;
    s->u_ready = 0;
    if ((st = choose_index(s)) != VPDS_OK) return st;
    run->implicit = 1;
    run->pos = 0;
    vpdsi_cells_layout(&run->cur, d, run->n0, 0);
    vpdsi_cells_layout(&run->next, d, run->n0, 0);
    if (s->n > 0) {
        run->phase = VPDSI_FILTER;
    } else {
        run->phase = VPDSI_DARTS;
        run->darts_left = darts_for(total, 0);
    }
    if (total > s->stats.peak_active_cells) s->stats.peak_active_cells = total;
    if (s->stats.levels < 1) s->stats.levels = 1;
    return VPDS_OK;
}

static void cell_coords(const vpds_sampler *s, uint64_t idx, uint64_t *c)
{
    const vpdsi_run *run = &s->run;
    int k;
    if (run->implicit) {
        for (k = 0; k < s->dim; k++) {
            c[k] = idx % run->n0[k];
            idx /= run->n0[k];
        }
    } else {
        vpdsi_cells_get(&run->cur, (size_t)idx, s->dim, c);
    }
}

double vpdsi_cell_box(const vpds_sampler *s, unsigned level, const uint64_t *c, double *lo,
                      double *hi)
{
    const vpdsi_run *run = &s->run;
    double diag2 = 0;
    int k;
    for (k = 0; k < s->dim; k++) {
        double side = ldexp(run->side0[k], -(int)level);
        uint64_t last = (run->n0[k] << level) - 1;
        lo[k] = s->lo[k] + (double)c[k] * side;
        hi[k] = c[k] == last ? s->hi[k] : s->lo[k] + (double)(c[k] + 1) * side;
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    return diag2;
}

static unsigned cur_level(const vpds_sampler *s) { return s->run.implicit ? 0 : s->run.cur.level; }

static uint64_t cur_count(const vpds_sampler *s)
{
    return s->run.implicit ? s->run.base_count : (uint64_t)s->run.cur.count;
}

/* n darts into out (n*dim): a cell uniformly, then a point uniformly in it; in weighted mode
 * one more uniform per dart into u, for its acceptance (Eq. 12). */
static void draw_darts(const vpds_sampler *s, vpdsi_rng *rng, size_t n, double *out, double *u)
{
    uint64_t c[VPDS_MAX_DIM], total = cur_count(s);
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM];
    unsigned level = cur_level(s);
    size_t j;
    int k, d = s->dim;
    for (j = 0; j < n; j++) {
        cell_coords(s, vpdsi_rng_below(rng, total), c);
        vpdsi_cell_box(s, level, c, lo, hi);
        for (k = 0; k < d; k++) {
            double v = lo[k] + vpdsi_rng_unit(rng) * (hi[k] - lo[k]);
            out[j * (size_t)d + (size_t)k] = v > hi[k] ? hi[k] : v;
        }
        if (u) u[j] = vpdsi_rng_unit(rng);
    }
}

static vpds_status reserve_buffers(vpds_sampler *s, size_t n)
{
    size_t nx;
    if (vpdsi_mul_size(n, (size_t)s->dim, &nx) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->buf_x, &s->cap_buf_x, nx, sizeof(double)) ||
        vpdsi_mem_reserve(&s->mem, (void **)&s->buf_r, &s->cap_buf_r, n, sizeof(double))) {
        vpdsi_set_error(s, "out of memory for a chunk of %zu points", n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    return VPDS_OK;
}

static int32_t grid_conflict(const vpds_sampler *s, const double *y, double reach)
{
    const vpdsi_bgrid *g = &s->grid;
    const int32_t *cell = g->cell + vpdsi_bgrid_locate(g, y);
    double reach2 = reach * reach;
    size_t j;
    int k, d = s->dim;
    if (cell[0] >= 0) return cell[0]; /* a cell holds one sample: any other point conflicts */
    for (j = 0; j < g->n_stencil; j++) {
        int32_t i = cell[g->stencil[j]];
        if (i >= 0) {
            const double *x = s->x + (size_t)i * (size_t)d;
            double d2 = 0;
            for (k = 0; k < d; k++) d2 += (y[k] - x[k]) * (y[k] - x[k]);
            if (d2 < reach2) return i;
        }
    }
    return -1;
}

/* An error at dart j of a chunk: keep the darts before it, as a pause would, and spend no
 * draw on the rest (a retry throws the same darts). */
static void keep_darts_before(vpds_sampler *s, const vpdsi_rng *start, size_t j, int weighted)
{
    s->rng = *start;
    draw_darts(s, &s->rng, j, s->buf_x, weighted ? s->buf_u : NULL);
    s->run.darts_left -= j;
    s->stats.darts += j;
}

static vpds_status darts_chunk(vpds_sampler *s, size_t n)
{
    int d = s->dim;
    int varying = s->sizing.kind != VPDSI_SIZING_CONSTANT;
    int weighted = s->weighted && varying;
    double scale = s->run.t * s->inhibition;
    vpdsi_rng start = s->rng;
    vpdsi_kd_samples view;
    vpds_status st;
    size_t j;
    if ((st = reserve_buffers(s, n)) != VPDS_OK) return st;
    if ((st = vpdsi_reserve_samples(s, n)) != VPDS_OK) return st;
    if (weighted && vpdsi_mem_reserve(&s->mem, (void **)&s->buf_u, &s->cap_buf_u, n, sizeof(double))) {
        vpdsi_set_error(s, "out of memory for a chunk of %zu darts", n);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    draw_darts(s, &s->rng, n, s->buf_x, weighted ? s->buf_u : NULL);
    if (varying) {
        st = vpdsi_sizing_eval(&s->sizing, s->buf_x, n, s->buf_r, s->err, sizeof s->err);
        if (st != VPDS_OK) {
            s->rng = start; /* no draw spent: a retry throws the same darts */
            return st;
        }
    } else {
        for (j = 0; j < n; j++) s->buf_r[j] = s->sizing.radius;
    }
    if (weighted) {
        /* Eq. 12 by rejection: keep a dart with probability (r_min / r(y))^d, so accepted darts
         * have density proportional to 1 / r^d over the free region */
        for (j = 0; j < n; j++) {
            if (s->buf_r[j] < s->sizing.rmin) {
                char py[256];
                vpdsi_format_point(py, sizeof py, s->buf_x + j * (size_t)d, d);
                vpdsi_set_error(s, "sizing returned r = %.17g at x = (%s), below radius_min = %.17g",
                                s->buf_r[j], py, s->sizing.rmin);
                s->rng = start;
                return VPDS_ERR_SIZING;
            }
            {
                double ratio = s->sizing.rmin / s->buf_r[j], keep = 1;
                int k;
                for (k = 0; k < d; k++) keep *= ratio;
                s->buf_u[j] = s->buf_u[j] < keep ? 1.0 : 0.0;
            }
        }
    }
    for (j = 0; j < n; j++) {
        const double *y = s->buf_x + j * (size_t)d;
        int32_t witness = -1, hit;
        if (weighted && s->buf_u[j] == 0.0) continue;
        if (s->grid_mode) {
            hit = grid_conflict(s, y, scale * s->sizing.radius);
        } else {
            view = vpdsi_samples_view(s);
            hit = vpdsi_kd_conflict(&s->tree, &view, y, s->buf_r[j], (int)s->rule, scale,
                                    varying ? s->sizing.lipschitz : -1.0, &witness);
        }
        if (hit == -2) {
            char py[256], px[256];
            const double *x = s->x + (size_t)witness * (size_t)d;
            double dist = 0;
            int k;
            for (k = 0; k < d; k++) dist += (y[k] - x[k]) * (y[k] - x[k]);
            dist = sqrt(dist);
            vpdsi_format_point(py, sizeof py, y, d);
            vpdsi_format_point(px, sizeof px, x, d);
            vpdsi_set_error(s, "sizing breaks lipschitz = %g: r = %.17g at (%s) and r = %.17g at"
                            " (%s), distance %.17g, slope %.17g", s->sizing.lipschitz,
                            s->buf_r[j], py, s->r[witness], px, dist,
                            fabs(s->buf_r[j] - s->r[witness]) / dist);
            keep_darts_before(s, &start, j, weighted);
            return VPDS_ERR_LIPSCHITZ;
        }
        if (hit == -1 && s->domain) {
            double phi;
            if ((st = vpdsi_domain_at(s, y, &phi)) != VPDS_OK) {
                keep_darts_before(s, &start, j, weighted);
                return st;
            }
            if (phi > 0) hit = -4; /* outside the domain: rejected, as uniform over it wants */
        }
        if (hit == -1 && s->two_radii) {
            /* Section 3.1, first option: the dart must cover a point not yet covered */
            int found = 0;
            st = VPDS_OK;
            if (vpdsi_uncovered_nearest(s, y) > vpdsi_coverage_reach(s, s->buf_r[j]) + s->u_half)
                found = 0; /* no cell that may hold an uncovered point is within reach */
            else
                st = vpdsi_uncovered_in(s, y, y, s->buf_r[j], &found);
            if (st != VPDS_OK) {
                keep_darts_before(s, &start, j, weighted);
                return st;
            }
            if (!found) hit = -3;
        }
        if (hit == -1) {
            vpdsi_append_sample(s, y, s->buf_r[j], s->run.t, 0);
            s->stats.accepted++;
        }
    }
    s->run.darts_left -= n;
    s->stats.darts += n;
    return VPDS_OK;
}

static int box_covered(const vpds_sampler *s, const double *lo, const double *hi, double r_lo,
                       double scale)
{
    vpdsi_kd_samples view = vpdsi_samples_view(s);
    return vpdsi_kd_box_covered(&s->tree, &view, s->cand, s->n_cand, lo, hi, r_lo, (int)s->rule, scale);
}

/* Which of the 2^d children of cell c are covered whole by one candidate. A child's farthest
 * point from x is, on each axis, the farther end of its half; so per candidate all children's
 * squared farthest distances are sums of 2 values per axis, built child by child from a
 * neighbour that differs in one axis. Bit b of covered is child b (bit k: upper half on axis k). */
static void children_covered(const vpds_sampler *s, unsigned level, const uint64_t *c, double r_lo,
                             double scale, uint64_t *covered)
{
    int d = s->dim, k;
    unsigned children = 1u << d, b;
    double lo[VPDS_MAX_DIM], mid[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], sums[1u << VPDS_MAX_DIM];
    uint64_t cc[VPDS_MAX_DIM] = {0};
    size_t j;
    for (k = 0; k < d; k++) cc[k] = 2 * c[k];
    vpdsi_cell_box(s, level + 1, cc, lo, mid);
    for (k = 0; k < d; k++) cc[k] = 2 * c[k] + 1;
    vpdsi_cell_box(s, level + 1, cc, mid, hi);
    for (j = 0; j < s->n_cand; j++) {
        const double *x = s->x + (size_t)s->cand[j] * (size_t)d;
        double f = scale * vpdsi_rule_f(s->rule, s->r[s->cand[j]], r_lo), f2 = f * f;
        double far[VPDS_MAX_DIM][2], least = 0;
        if (!(f > 0)) continue;
        for (k = 0; k < d; k++) {
            double a = vpdsi_axis_far(x[k], lo[k], mid[k], s->period[k]);
            double z = vpdsi_axis_far(x[k], mid[k], hi[k], s->period[k]);
            far[k][0] = a * a;
            far[k][1] = z * z;
            least += far[k][0] < far[k][1] ? far[k][0] : far[k][1];
        }
        if (least > f2) continue; /* covers no child */
        sums[0] = 0;
        for (k = 0; k < d; k++) sums[0] += far[k][0];
        if (sums[0] <= f2) covered[0] |= 1u;
        for (b = 1; b < children; b++) {
            unsigned low = 0;
            while (!((b >> low) & 1u)) low++;
            sums[b] = sums[b & (b - 1)] - far[low][0] + far[low][1];
            if (sums[b] <= f2) covered[b >> 6] |= UINT64_C(1) << (b & 63u);
        }
    }
}

/* A cell that straddles the domain's boundary (centre's sdf phi): mark as covered each kept
 * child that lies outside the domain, and, with one radius, each whose part inside the domain
 * is covered by the union of disks (a search inside it); else such children would split along
 * the boundary down to the precision limit. Without a split the "child" is the cell itself. */
static vpds_status drop_outside_children(vpds_sampler *s, unsigned level, const uint64_t *c,
                                         int split, const double *centre, double phi,
                                         uint64_t *covered)
{
    int d = s->dim, k;
    unsigned children = split ? 1u << d : 1u, b;
    uint64_t cc[VPDS_MAX_DIM];
    vpds_status st;
    for (b = 0; b < children; b++) {
        double clo[VPDS_MAX_DIM], chi[VPDS_MAX_DIM], cm[VPDS_MAX_DIM], half, phi_c = phi;
        int found = 1;
        if (covered[b >> 6] >> (b & 63u) & 1u) continue;
        for (k = 0; k < d; k++) cc[k] = split ? 2 * c[k] + ((b >> k) & 1u) : c[k];
        half = 0.5 * sqrt(vpdsi_cell_box(s, split ? level + 1 : level, cc, clo, chi));
        for (k = 0; k < d; k++) cm[k] = 0.5 * (clo[k] + chi[k]);
        if (split) {
            if ((st = vpdsi_domain_at(s, cm, &phi_c)) != VPDS_OK) return st;
            if ((st = vpdsi_domain_check_pair(s, centre, phi, cm, phi_c)) != VPDS_OK) return st;
        }
        if (phi_c <= -half) continue; /* inside, whole: the usual rules apply */
        if (phi_c <= half && !s->two_radii &&
            (st = vpdsi_uncovered_in(s, clo, chi, 0.0, &found)) != VPDS_OK)
            return st;
        if (phi_c > half || !found) covered[b >> 6] |= UINT64_C(1) << (b & 63u);
    }
    return VPDS_OK;
}

/* Sweep n cells from run->pos: drop covered ones, keep the others (split: their uncovered
 * children) in run->next. run->pos advances cell by cell, so an error mid-chunk loses nothing. */
static vpds_status sweep_chunk(vpds_sampler *s, size_t n, int split)
{
    vpdsi_run *run = &s->run;
    int d = s->dim, k;
    unsigned level = cur_level(s), children = split ? 1u << d : 1u, b;
    int varying = s->sizing.kind != VPDSI_SIZING_CONSTANT;
    /* r over the cell: for a rule that reads r(y), and for the reach of two radii' V */
    int need_r = varying && (vpdsi_rule_uses_y(s->rule) || s->two_radii);
    /* a cell is dropped inside one inhibition disk (with one radius: one coverage disk) */
    double scale = run->t * s->inhibition, L = s->sizing.lipschitz;
    uint64_t c[VPDS_MAX_DIM], cc[VPDS_MAX_DIM];
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], centre[VPDS_MAX_DIM], phi = -INFINITY;
    size_t j, need;
    vpds_status st;
    if (vpdsi_mul_size(n, children, &need) ||
        vpdsi_cells_reserve(&run->next, &s->mem, run->next.count + need) ||
        (s->two_radii && vpdsi_mem_reserve(&s->mem, (void **)&s->next_u, &s->cap_next_u,
                                           run->next.count + need, 1))) {
        vpdsi_set_error(s, "out of memory for the active cells of level %u", run->next.level);
        return VPDS_ERR_OUT_OF_MEMORY;
    }
    if (need_r) {
        /* r at the cell centres bounds r over each cell through L */
        if ((st = reserve_buffers(s, n)) != VPDS_OK) return st;
        for (j = 0; j < n; j++) {
            cell_coords(s, run->pos + j, c);
            vpdsi_cell_box(s, level, c, lo, hi);
            for (k = 0; k < d; k++) s->buf_x[j * (size_t)d + (size_t)k] = 0.5 * (lo[k] + hi[k]);
        }
        st = vpdsi_sizing_eval(&s->sizing, s->buf_x, n, s->buf_r, s->err, sizeof s->err);
        if (st != VPDS_OK) return st;
    }
    for (j = 0; j < n; j++) {
        double h = sqrt(vpdsi_cell_box(s, level, (cell_coords(s, run->pos, c), c), lo, hi));
        double r_lo = s->sizing.radius, r_hi = s->sizing.radius;
        uint64_t covered[4] = {0, 0, 0, 0};
        uint8_t flag[1u << VPDS_MAX_DIM]; /* two radii: the child may hold an uncovered point */
        vpdsi_kd_samples view = vpdsi_samples_view(s);
        if (need_r) {
            r_lo = s->buf_r[j] - L * h / 2;
            r_hi = s->buf_r[j] + L * h / 2;
        }
        if (s->domain) {
            for (k = 0; k < d; k++) centre[k] = 0.5 * (lo[k] + hi[k]);
            if ((st = vpdsi_domain_at(s, centre, &phi)) != VPDS_OK) return st;
            if (phi > 0.5 * h) { /* outside the domain, whole */
                run->pos++;
                continue;
            }
        }
        s->n_cand = 0;
        if (s->grid_mode) {
            uint64_t base[VPDS_MAX_DIM];
            for (k = 0; k < d; k++) base[k] = c[k] >> level; /* the base cell holding this one */
            s->n_cand = vpdsi_bgrid_near(&s->grid, vpdsi_bgrid_index(&s->grid, base), s->cand);
        } else if (vpdsi_kd_gather(&s->tree, &view, lo, hi, r_hi, (int)s->rule,
                                   s->two_radii ? run->t * s->coverage : scale, split,
                                   &s->mem, &s->cand, &s->n_cand, &s->cap_cand)) {
            vpdsi_set_error(s, "out of memory gathering the samples near a cell");
            return VPDS_ERR_OUT_OF_MEMORY;
        }
        if (box_covered(s, lo, hi, r_lo, scale)) {
            run->pos++;
            continue;
        }
        if (split) children_covered(s, level, c, r_lo, scale, covered);
        if (s->domain && phi > -0.5 * h &&
            (st = drop_outside_children(s, level, c, split, centre, phi, covered)) != VPDS_OK)
            return st;
        if (s->two_radii) {
            /* which kept children may hold an uncovered point: not inside one coverage disk
             * (the gather above, at the larger coverage reach, found every candidate), and
             * not shown covered by a search inside them; decided before anything is kept */
            uint64_t cov_c[4] = {0, 0, 0, 0};
            double scale_c = run->t * s->coverage;
            if (box_covered(s, lo, hi, r_lo, scale_c)) {
                cov_c[0] = cov_c[1] = cov_c[2] = cov_c[3] = ~UINT64_C(0);
            } else if (split) {
                children_covered(s, level, c, r_lo, scale_c, cov_c);
            }
            for (b = 0; b < children; b++) {
                double clo[VPDS_MAX_DIM], chi[VPDS_MAX_DIM];
                int found = 0;
                flag[b] = 0;
                if ((covered[b >> 6] >> (b & 63u) & 1u) || (cov_c[b >> 6] >> (b & 63u) & 1u))
                    continue;
                for (k = 0; k < d; k++) cc[k] = split ? 2 * c[k] + ((b >> k) & 1u) : c[k];
                vpdsi_cell_box(s, split ? level + 1 : level, cc, clo, chi);
                if ((st = vpdsi_uncovered_in(s, clo, chi, 0.0, &found)) != VPDS_OK) return st;
                flag[b] = (uint8_t)found;
            }
        }
        run->pos++;
        for (b = 0; b < children; b++) {
            if (covered[b >> 6] >> (b & 63u) & 1u) continue;
            if (s->two_radii) s->next_u[run->next.count] = flag[b];
            for (k = 0; k < d; k++) cc[k] = split ? 2 * c[k] + ((b >> k) & 1u) : c[k];
            vpdsi_cells_push(&run->next, d, cc);
        }
    }
    return VPDS_OK;
}

/* Two radii (Figure 2): keep a new cell only if a cell that may hold an uncovered point lies
 * within the coverage reach of it; kept cells are compacted in place, in order. */
static vpds_status vfilter_chunk(vpds_sampler *s, size_t n)
{
    vpdsi_run *run = &s->run;
    int d = s->dim, k;
    int varying = s->sizing.kind != VPDSI_SIZING_CONSTANT;
    uint64_t c[VPDS_MAX_DIM];
    double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], centre[VPDS_MAX_DIM];
    size_t j;
    vpds_status st;
    if (!s->u_ready && (st = vpdsi_uncovered_index(s)) != VPDS_OK) return st;
    if (varying) {
        if ((st = reserve_buffers(s, n)) != VPDS_OK) return st;
        for (j = 0; j < n; j++) {
            vpdsi_cells_get(&run->next, (size_t)run->vpos + j, d, c);
            vpdsi_cell_box(s, run->next.level, c, lo, hi);
            for (k = 0; k < d; k++) s->buf_x[j * (size_t)d + (size_t)k] = 0.5 * (lo[k] + hi[k]);
        }
        st = vpdsi_sizing_eval(&s->sizing, s->buf_x, n, s->buf_r, s->err, sizeof s->err);
        if (st != VPDS_OK) return st;
    }
    for (j = 0; j < n; j++) {
        size_t i = (size_t)run->vpos;
        double h = 0.5 * sqrt(vpdsi_cell_box(s, run->next.level, (vpdsi_cells_get(&run->next, i, d, c), c), lo, hi));
        double r_hi = varying ? s->buf_r[j] + s->sizing.lipschitz * h : s->sizing.radius;
        for (k = 0; k < d; k++) centre[k] = 0.5 * (lo[k] + hi[k]);
        if (vpdsi_uncovered_nearest(s, centre) <= vpdsi_coverage_reach(s, r_hi) + h + s->u_half) {
            vpdsi_cells_move(&run->next, i, (size_t)run->wpos);
            s->next_u[run->wpos] = s->next_u[i];
            run->wpos++;
        }
        run->vpos++;
    }
    return VPDS_OK;
}

/* The sweep of a level is complete: its output becomes the active cells. */
static void finish_sweep(vpds_sampler *s, int split)
{
    vpdsi_run *run = &s->run;
    vpdsi_cells tmp = run->cur;
    run->cur = run->next;
    run->next = tmp;
    run->implicit = 0;
    run->pos = 0;
    if (run->cur.count > s->stats.peak_active_cells) s->stats.peak_active_cells = run->cur.count;
    if (run->cur.level + 1 > s->stats.levels) s->stats.levels = run->cur.level + 1;
    if (run->cur.count == 0) {
        run->phase = VPDSI_DONE;
        s->stats.delta = 0;
    } else if (!split && run->phase == VPDSI_SWEEP) {
        /* precision limit: report how far from maximal the set may be */
        uint64_t c[VPDS_MAX_DIM] = {0};
        double lo[VPDS_MAX_DIM], hi[VPDS_MAX_DIM], worst = 0;
        size_t i;
        for (i = 0; i < run->cur.count; i++) {
            double dg;
            vpdsi_cells_get(&run->cur, i, s->dim, c);
            dg = sqrt(vpdsi_cell_box(s, run->cur.level, c, lo, hi));
            if (dg > worst) worst = dg;
        }
        s->stats.delta = worst;
        run->phase = VPDSI_DONE;
    } else {
        run->phase = VPDSI_DARTS;
        run->darts_left = darts_for(run->cur.count, run->cur.level);
    }
    if (run->phase == VPDSI_DONE) vpdsi_mps_release(s);
}

static void begin_sweep(vpds_sampler *s, int split)
{
    vpdsi_cells_layout(&s->run.next, s->dim, s->run.n0, cur_level(s) + (split ? 1u : 0u));
    s->run.pos = 0;
}

vpds_status vpdsi_mps_run(vpds_sampler *s)
{
    vpdsi_run *run = &s->run;
    uint64_t work = 0;
    vpds_status st = VPDS_OK;
    if (run->phase == VPDSI_DONE) return VPDS_OK;
    if (run->phase == VPDSI_IDLE) {
        if ((st = setup(s)) != VPDS_OK) return st;
        if (run->phase == VPDSI_FILTER) begin_sweep(s, 0);
    }
    for (;;) {
        uint64_t limit = CHUNK, before;
        if (run->phase == VPDSI_DONE && s->n == 0 && s->domain) {
            /* nothing to sample: say so, and leave the sampler as it was */
            vpdsi_mps_reset(s, run->t);
            vpdsi_set_error(s, "domain: no point of the box with sdf <= 0 was found (the domain is"
                            " empty, or too thin for darts to land in)");
            return VPDS_ERR_DOMAIN;
        }
        if (run->phase == VPDSI_DONE) return VPDS_OK;
        if (s->budget && work >= s->budget) return VPDS_PAUSED;
        if (s->budget && s->budget - work < limit) limit = s->budget - work;
        switch (run->phase) {
        case VPDSI_FILTER:
        case VPDSI_SWEEP: {
            int split = run->phase == VPDSI_SWEEP && cur_level(s) < run->max_level;
            uint64_t total = cur_count(s);
            before = run->pos;
            if (total - run->pos < limit) limit = total - run->pos;
            st = sweep_chunk(s, (size_t)limit, split);
            work += run->pos - before;
            if (st != VPDS_OK) return st;
            if (run->pos == total) {
                if (s->two_radii) {
                    run->vsplit = split | (run->phase == VPDSI_FILTER ? 2 : 0);
                    run->vpos = run->wpos = 0;
                    s->u_ready = 0;
                    run->phase = VPDSI_VFILTER;
                } else {
                    finish_sweep(s, split);
                }
            }
            break;
        }
        case VPDSI_VFILTER: {
            uint64_t total = run->next.count;
            before = run->vpos;
            if (total - run->vpos < limit) limit = total - run->vpos;
            st = vfilter_chunk(s, (size_t)limit);
            work += run->vpos - before;
            if (st != VPDS_OK) return st;
            if (run->vpos == total) {
                run->next.count = (size_t)run->wpos;
                /* finish_sweep tells a precision stop by the phase: restore the sweep's */
                run->phase = run->vsplit & 2 ? VPDSI_FILTER : VPDSI_SWEEP;
                finish_sweep(s, run->vsplit & 1);
            }
            break;
        }
        case VPDSI_DARTS:
            if (run->darts_left == 0) {
                run->phase = VPDSI_SWEEP;
                begin_sweep(s, cur_level(s) < run->max_level);
                continue;
            }
            if (run->darts_left < limit) limit = run->darts_left;
            before = run->darts_left;
            st = darts_chunk(s, (size_t)limit);
            work += before - run->darts_left;
            if (st != VPDS_OK) return st;
            break;
        default:
            return VPDS_ERR_STATE;
        }
        if (s->progress) {
            vpds_progress p;
            p.darts = s->stats.darts;
            p.samples = s->n;
            p.active_cells = run->phase == VPDSI_DONE ? 0 : cur_count(s);
            p.level = cur_level(s);
            p.t = run->t;
            if (s->progress(&p, s->progress_user) != 0)
                return run->phase == VPDSI_DONE ? VPDS_OK : VPDS_PAUSED;
        }
    }
}
