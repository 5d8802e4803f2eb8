#include "kdtree.h"
#include "proximity.h"
#include <math.h>
#include <string.h>

#define BOX_LO(t, n) ((t)->box + (size_t)(n) * 2 * (size_t)(t)->dim)
#define BOX_HI(t, n) (BOX_LO(t, n) + (t)->dim)
#define STACK_MAX (VPDSI_KD_MAX_DEPTH + 8)

void vpdsi_kd_init(vpdsi_kdtree *t, int dim)
{
    memset(t, 0, sizeof *t);
    t->dim = dim;
}

void vpdsi_kd_set_period(vpdsi_kdtree *t, const double *period)
{
    int k;
    for (k = 0; k < t->dim; k++) t->period[k] = period ? period[k] : 0.0;
}

void vpdsi_kd_release(vpdsi_kdtree *t, vpdsi_mem *m)
{
    vpdsi_mem_free(m, t->nodes, t->cap_nodes * sizeof *t->nodes);
    vpdsi_mem_free(m, t->box, t->cap_box * sizeof *t->box);
    vpdsi_mem_free(m, t->next, t->cap_next * sizeof *t->next);
    t->nodes = NULL;
    t->box = NULL;
    t->next = NULL;
    t->n_nodes = t->cap_nodes = t->cap_box = t->cap_next = 0;
}

void vpdsi_kd_clear(vpdsi_kdtree *t) { t->n_nodes = 0; }

int vpdsi_kd_reserve(vpdsi_kdtree *t, vpdsi_mem *m, size_t n_total, size_t more)
{
    size_t nodes = t->n_nodes + 2 * more + 1, boxes;
    if (vpdsi_mul_size(nodes, 2 * (size_t)t->dim, &boxes) != 0) return -1;
    if (vpdsi_mem_reserve(m, (void **)&t->next, &t->cap_next, n_total, sizeof *t->next)) return -1;
    if (vpdsi_mem_reserve(m, (void **)&t->nodes, &t->cap_nodes, nodes, sizeof *t->nodes)) return -1;
    {
        /* keep the box array in step with the node array's capacity */
        size_t want = t->cap_nodes * 2 * (size_t)t->dim;
        if (vpdsi_mem_reserve(m, (void **)&t->box, &t->cap_box, want, sizeof *t->box)) return -1;
    }
    return 0;
}

static void leaf_init(vpdsi_kdtree *t, int32_t n)
{
    vpdsi_kd_node *nd = &t->nodes[n];
    nd->left = nd->right = -1;
    nd->head = -1;
    nd->count = 0;
    nd->split = 0;
    nd->rmax = 0;
    nd->axis = 0;
    nd->pad = 0;
}

static void node_add(vpdsi_kdtree *t, int32_t n, const double *p, double r, int empty)
{
    double *lo = BOX_LO(t, n), *hi = BOX_HI(t, n);
    int k;
    for (k = 0; k < t->dim; k++) {
        if (empty || p[k] < lo[k]) lo[k] = p[k];
        if (empty || p[k] > hi[k]) hi[k] = p[k];
    }
    if (empty || r > t->nodes[n].rmax) t->nodes[n].rmax = r;
}

/* Split a full leaf at the mean of its samples along its widest axis (a value strictly inside
 * the box's extent, so both sides get samples). Leaves of identical points stay whole. */
static void leaf_split(vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t n)
{
    const double *lo = BOX_LO(t, n), *hi = BOX_HI(t, n);
    int k, axis = 0, d = t->dim;
    double best = -1, sum = 0, split;
    int32_t i, next, children[2];
    vpdsi_kd_node *nd;
    for (k = 0; k < d; k++)
        if (hi[k] - lo[k] > best) {
            best = hi[k] - lo[k];
            axis = k;
        }
    if (!(best > 0)) return;
    for (i = t->nodes[n].head; i >= 0; i = t->next[i]) sum += s->x[(size_t)i * d + axis];
    split = sum / t->nodes[n].count;
    if (!(split > lo[axis]) || split > hi[axis]) split = hi[axis];
    children[0] = (int32_t)t->n_nodes;
    children[1] = (int32_t)t->n_nodes + 1;
    t->n_nodes += 2;
    leaf_init(t, children[0]);
    leaf_init(t, children[1]);
    nd = &t->nodes[n];
    for (i = nd->head; i >= 0; i = next) {
        const double *p = s->x + (size_t)i * d;
        int32_t c = children[p[axis] < split ? 0 : 1];
        next = t->next[i];
        node_add(t, c, p, s->r[i], t->nodes[c].count == 0);
        t->next[i] = t->nodes[c].head;
        t->nodes[c].head = i;
        t->nodes[c].count++;
    }
    nd->left = children[0];
    nd->right = children[1];
    nd->axis = axis;
    nd->split = split;
    nd->head = -1;
    nd->count = 0;
}

void vpdsi_kd_insert(vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i)
{
    const double *p = s->x + (size_t)i * t->dim;
    double r = s->r[i];
    int32_t n = 0;
    int depth = 0;
    if (t->n_nodes == 0) {
        t->n_nodes = 1;
        leaf_init(t, 0);
        node_add(t, 0, p, r, 1);
    } else {
        node_add(t, 0, p, r, 0);
    }
    while (t->nodes[n].left >= 0) {
        vpdsi_kd_node *nd = &t->nodes[n];
        n = p[nd->axis] < nd->split ? nd->left : nd->right;
        depth++;
        node_add(t, n, p, r, 0);
    }
    t->next[i] = t->nodes[n].head;
    t->nodes[n].head = i;
    t->nodes[n].count++;
    if (t->nodes[n].count > VPDSI_KD_LEAF && depth < VPDSI_KD_MAX_DEPTH) leaf_split(t, s, n);
}

double vpdsi_box_mindist2(const vpdsi_kdtree *t, const double *p, const double *lo, const double *hi)
{
    double s = 0;
    int k;
    for (k = 0; k < t->dim; k++) {
        double e = vpdsi_axis_gap(p[k], lo[k], hi[k], t->period[k]);
        s += e * e;
    }
    return s;
}

double vpdsi_box_maxdist2(const vpdsi_kdtree *t, const double *p, const double *lo, const double *hi)
{
    double s = 0;
    int k;
    for (k = 0; k < t->dim; k++) {
        double e = vpdsi_axis_far(p[k], lo[k], hi[k], t->period[k]);
        s += e * e;
    }
    return s;
}

#define dist2(a, b, dim) vpdsi_torus_dist2((a), (b), (dim), t->period)

/* The per-sample tests, shared by the tree walks and the list versions so that both give the
 * same bits. */
static double conflict_reach(const vpdsi_kd_samples *s, int32_t i, double ry, int rule,
                             double scale)
{
    return scale * vpdsi_rule_f((vpds_rule)rule, s->r[i], ry);
}

static double ratio(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i, const double *y,
                    double slack, double ry, int rule)
{
    double fi = vpdsi_rule_f((vpds_rule)rule, s->r[i], ry);
    return (sqrt(dist2(y, s->x + (size_t)i * (size_t)t->dim, t->dim)) + slack) / fi;
}

static int covers_box(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i, const double *lo,
                      const double *hi, double r_lo, int rule, double scale)
{
    double f = scale * vpdsi_rule_f((vpds_rule)rule, s->r[i], r_lo);
    return f > 0 && vpdsi_box_maxdist2(t, s->x + (size_t)i * (size_t)t->dim, lo, hi) <= f * f;
}

int32_t vpdsi_kd_conflict(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *y,
                          double ry, int rule, double scale, double lipschitz, int32_t *witness)
{
    int32_t stack[STACK_MAX];
    int top = 0, d = t->dim;
    if (t->n_nodes == 0) return -1;
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        double reach = scale * vpdsi_rule_f((vpds_rule)rule, nd->rmax, ry);
        if (vpdsi_box_mindist2(t, y, BOX_LO(t, n), BOX_HI(t, n)) >= reach * reach) continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i]) {
                int hit = vpdsi_prox_conflict(s, i, d, t->period, y, ry, rule, scale, lipschitz);
                if (hit == -2) {
                    *witness = i;
                    return -2;
                }
                if (hit) return i;
            }
        } else {
            int near = y[nd->axis] < nd->split;
            stack[top++] = near ? nd->right : nd->left;
            stack[top++] = near ? nd->left : nd->right;
        }
    }
    return -1;
}

static int push_index(vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap, int32_t i)
{
    if (*count == *cap && vpdsi_mem_reserve(m, (void **)out, cap, *count + 1, sizeof **out))
        return -1;
    (*out)[(*count)++] = i;
    return 0;
}

int vpdsi_kd_gather(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *lo,
                    const double *hi, double r_hi, int rule, double scale, int split,
                    vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap)
{
    int32_t stack[STACK_MAX];
    int top = 0, d = t->dim, k;
    double c0[VPDS_MAX_DIM], c1[VPDS_MAX_DIM], w[VPDS_MAX_DIM];
    if (t->n_nodes == 0) return 0;
    vpdsi_prox_gather_centres(d, lo, hi, split, c0, c1, w);
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        const double *blo = BOX_LO(t, n), *bhi = BOX_HI(t, n);
        double reach = scale * vpdsi_rule_f((vpds_rule)rule, nd->rmax, r_hi), need = 0;
        for (k = 0; k < d; k++) {
            double f = vpdsi_prox_far_bound(blo[k], bhi[k], c0[k], c1[k], w[k], t->period[k]);
            need += f * f;
        }
        if (need > reach * reach) continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i])
                if (vpdsi_prox_may_cover(s, i, t->dim, t->period, c0, c1, w, r_hi, rule, scale) &&
                    push_index(m, out, count, cap, i))
                    return -1;
        } else {
            stack[top++] = nd->left;
            stack[top++] = nd->right;
        }
    }
    return 0;
}

int vpdsi_kd_radius(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *p,
                    double radius, vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap)
{
    int32_t stack[STACK_MAX];
    int top = 0, d = t->dim;
    double r2 = radius * radius;
    if (t->n_nodes == 0) return 0;
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        if (vpdsi_box_mindist2(t, p, BOX_LO(t, n), BOX_HI(t, n)) > r2) continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i])
                if (dist2(p, s->x + (size_t)i * d, d) <= r2 &&
                    push_index(m, out, count, cap, i))
                    return -1;
        } else {
            stack[top++] = nd->left;
            stack[top++] = nd->right;
        }
    }
    return 0;
}

int32_t vpdsi_kd_box_holder(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *cand,
                            size_t n, const double *lo, const double *hi, double r_lo, int rule,
                            double scale)
{
    size_t j;
    for (j = 0; j < n; j++)
        if (covers_box(t, s, cand[j], lo, hi, r_lo, rule, scale)) return cand[j];
    return -1;
}

int vpdsi_kd_box_covered(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *cand,
                         size_t n, const double *lo, const double *hi, double r_lo, int rule,
                         double scale)
{
    return vpdsi_kd_box_holder(t, s, cand, n, lo, hi, r_lo, rule, scale) >= 0;
}

double vpdsi_kd_min_ratio(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *y,
                          double slack, double ry, int rule, int32_t *arg)
{
    int32_t stack[STACK_MAX];
    int top = 0;
    double best = INFINITY;
    *arg = -1;
    if (t->n_nodes == 0) return best;
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        double f = vpdsi_rule_f((vpds_rule)rule, nd->rmax, ry);
        /* f is monotone in r(x): no sample of the node does better than its largest radius */
        if ((sqrt(vpdsi_box_mindist2(t, y, BOX_LO(t, n), BOX_HI(t, n))) + slack) >= best * f) continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i]) {
                double q = ratio(t, s, i, y, slack, ry, rule);
                if (q < best) {
                    best = q;
                    *arg = i;
                }
            }
        } else {
            int near = y[nd->axis] < nd->split;
            stack[top++] = near ? nd->right : nd->left;
            stack[top++] = near ? nd->left : nd->right;
        }
    }
    return best;
}

int vpdsi_kd_ratio_within(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *y,
                          double bound)
{
    int32_t stack[STACK_MAX];
    int top = 0;
    if (t->n_nodes == 0) return 0;
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        /* every sample of the node has a ratio of at least its box distance over rmax; the
         * margin covers the ulp by which a periodic box distance may exceed a sample's */
        if (!(sqrt(vpdsi_box_mindist2(t, y, BOX_LO(t, n), BOX_HI(t, n))) <= bound * nd->rmax * (1 + 1e-9)))
            continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i])
                if (ratio(t, s, i, y, 0.0, 0.0, (int)VPDS_RULE_PRIOR) <= bound) return 1;
        } else {
            int near = y[nd->axis] < nd->split;
            stack[top++] = near ? nd->right : nd->left;
            stack[top++] = near ? nd->left : nd->right;
        }
    }
    return 0;
}

/* ---- Candidate lists: the same tests over a list of sample indices instead of the tree ---- */

/* Gap between the intervals [a, b] and [lo, hi] along an axis of period P (0: open). */
static double interval_gap(double a, double b, double lo, double hi, double P)
{
    double best = lo > b ? lo - b : a > hi ? a - hi : 0, g;
    if (P > 0 && best > 0) {
        g = lo + P > b ? lo + P - b : a > hi + P ? a - (hi + P) : 0;
        if (g < best) best = g;
        g = lo - P > b ? lo - P - b : a > hi - P ? a - (hi - P) : 0;
        if (g < best) best = g;
    }
    return best;
}

/* Squared gap between node n's bounding box and the box [lo, hi], on the tree's torus. */
static double node_gap2(const vpdsi_kdtree *t, int32_t n, const double *lo, const double *hi)
{
    const double *blo = BOX_LO(t, n), *bhi = BOX_HI(t, n);
    double gap2 = 0;
    int k;
    for (k = 0; k < t->dim; k++) {
        double g = interval_gap(blo[k], bhi[k], lo[k], hi[k], t->period[k]);
        gap2 += g * g;
    }
    return gap2;
}

/* How far from the box a sample of radius r may lie and still matter (see kdtree.h). */
static double near_limit(double r, double r_bound, double scale, double slack)
{
    return scale * (r > r_bound ? r : r_bound) * (1 + 1e-9) + slack;
}

static int is_near(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i, const double *lo,
                   const double *hi, double r_bound, double scale, double slack)
{
    return vpdsi_prox_near(s, i, t->dim, t->period, lo, hi, r_bound, scale, slack);
}

int vpdsi_kd_near_box(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *lo,
                      const double *hi, double r_bound, double scale, double slack, size_t limit,
                      vpdsi_mem *m, int32_t **out, size_t *count, size_t *cap)
{
    int32_t stack[STACK_MAX];
    int top = 0;
    size_t end = *count + limit;
    if (t->n_nodes == 0) return 0;
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        double lim = near_limit(nd->rmax, r_bound, scale, slack);
        if (node_gap2(t, n, lo, hi) > lim * lim) continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i]) {
                if (!is_near(t, s, i, lo, hi, r_bound, scale, slack)) continue;
                if (*count == end) return 1;
                if (push_index(m, out, count, cap, i)) return -1;
            }
        } else {
            stack[top++] = nd->left;
            stack[top++] = nd->right;
        }
    }
    return 0;
}

size_t vpdsi_kd_filter_near(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *from,
                            size_t n, const double *lo, const double *hi, double r_bound,
                            double scale, double slack, int32_t *out)
{
    size_t j, count = 0;
    for (j = 0; j < n; j++)
        if (is_near(t, s, from[j], lo, hi, r_bound, scale, slack)) out[count++] = from[j];
    return count;
}

size_t vpdsi_kd_list_gather(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *from,
                            size_t n, const double *lo, const double *hi, double r_hi, int rule,
                            double scale, int split, int32_t *out)
{
    double c0[VPDS_MAX_DIM], c1[VPDS_MAX_DIM], w[VPDS_MAX_DIM];
    size_t j, count = 0;
    vpdsi_prox_gather_centres(t->dim, lo, hi, split, c0, c1, w);
    for (j = 0; j < n; j++)
        if (vpdsi_prox_may_cover(s, from[j], t->dim, t->period, c0, c1, w, r_hi, rule, scale))
            out[count++] = from[j];
    return count;
}

int32_t vpdsi_kd_list_conflict(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                               const int32_t *cand, size_t n, const double *y, double ry, int rule,
                               double scale)
{
    size_t j;
    for (j = 0; j < n; j++) {
        int32_t i = cand[j];
        double f = conflict_reach(s, i, ry, rule, scale);
        if (dist2(y, s->x + (size_t)i * (size_t)t->dim, t->dim) < f * f) return i;
    }
    return -1;
}

int vpdsi_kd_list_box_covered(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                              const int32_t *cand, size_t n, const double *lo, const double *hi,
                              double r_hi, double r_lo, int rule, double scale)
{
    double c0[VPDS_MAX_DIM], c1[VPDS_MAX_DIM], w[VPDS_MAX_DIM];
    size_t j;
    vpdsi_prox_gather_centres(t->dim, lo, hi, 0, c0, c1, w);
    for (j = 0; j < n; j++)
        if (vpdsi_prox_may_cover(s, cand[j], t->dim, t->period, c0, c1, w, r_hi, rule, scale) &&
            covers_box(t, s, cand[j], lo, hi, r_lo, rule, scale))
            return 1;
    return 0;
}

double vpdsi_kd_list_min_ratio(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                               const int32_t *cand, size_t n, const double *y, double slack,
                               double ry, int rule, int32_t *arg)
{
    double best = INFINITY;
    size_t j;
    if (arg) *arg = -1;
    for (j = 0; j < n; j++) {
        double q = ratio(t, s, cand[j], y, slack, ry, rule);
        if (q < best) {
            best = q;
            if (arg) *arg = cand[j];
        }
    }
    return best;
}

/* A sample's ratio over the box from below (nearest point, largest f) and from above. */
static double ratio_lb(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i,
                       const double *lo, const double *hi, double r_hi, int rule)
{
    double f = vpdsi_rule_f((vpds_rule)rule, s->r[i], r_hi);
    return f > 0 ? sqrt(vpdsi_box_mindist2(t, s->x + (size_t)i * (size_t)t->dim, lo, hi)) / f : 0;
}

static double ratio_ub(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, int32_t i,
                       const double *lo, const double *hi, double r_lo, int rule)
{
    double f = vpdsi_rule_f((vpds_rule)rule, s->r[i], r_lo);
    return f > 0 ? sqrt(vpdsi_box_maxdist2(t, s->x + (size_t)i * (size_t)t->dim, lo, hi)) / f
                 : INFINITY;
}

/* The samples of from whose lower bound comes within 1e-9 of best_ub, in order, into out (which
 * may be from: a kept one never moves up); their count. */
static size_t keep_within(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const int32_t *from,
                          size_t n, const double *lo, const double *hi, double r_hi, int rule,
                          double best_ub, int32_t *out)
{
    size_t j, count = 0;
    for (j = 0; j < n; j++)
        if (ratio_lb(t, s, from[j], lo, hi, r_hi, rule) <= best_ub * (1 + 1e-9)) out[count++] = from[j];
    return count;
}

size_t vpdsi_kd_list_ratio_candidates(const vpdsi_kdtree *t, const vpdsi_kd_samples *s,
                                      const int32_t *from, size_t n, const double *lo,
                                      const double *hi, double r_lo, double r_hi, int rule,
                                      int32_t *out)
{
    double best_ub = INFINITY, ub;
    size_t j;
    for (j = 0; j < n; j++) {
        ub = ratio_ub(t, s, from[j], lo, hi, r_lo, rule);
        if (ub < best_ub) best_ub = ub;
    }
    return keep_within(t, s, from, n, lo, hi, r_hi, rule, best_ub, out);
}

int vpdsi_kd_ratio_candidates(const vpdsi_kdtree *t, const vpdsi_kd_samples *s, const double *lo,
                              const double *hi, double r_lo, double r_hi, int rule, vpdsi_mem *m,
                              int32_t **out, size_t *count, size_t *cap)
{
    int32_t stack[STACK_MAX];
    int top = 0;
    size_t first = *count;
    double best_ub = INFINITY;
    if (t->n_nodes == 0) return 0;
    stack[top++] = 0;
    while (top > 0) {
        int32_t n = stack[--top];
        const vpdsi_kd_node *nd = &t->nodes[n];
        double f = vpdsi_rule_f((vpds_rule)rule, nd->rmax, r_hi);
        /* f is monotone in r(x): no sample of the node has a smaller lower bound */
        if (f > 0 && sqrt(node_gap2(t, n, lo, hi)) / f > best_ub * (1 + 1e-9)) continue;
        if (nd->left < 0) {
            int32_t i;
            for (i = nd->head; i >= 0; i = t->next[i]) {
                double ub = ratio_ub(t, s, i, lo, hi, r_lo, rule);
                if (ub < best_ub) best_ub = ub;
                if (ratio_lb(t, s, i, lo, hi, r_hi, rule) <= best_ub * (1 + 1e-9) &&
                    push_index(m, out, count, cap, i))
                    return -1;
            }
        } else {
            int near = 0.5 * (lo[nd->axis] + hi[nd->axis]) < nd->split;
            stack[top++] = near ? nd->right : nd->left;
            stack[top++] = near ? nd->left : nd->right;
        }
    }
    /* against the final bound, in order */
    *count = first + keep_within(t, s, *out + first, *count - first, lo, hi, r_hi, rule, best_ub,
                                 *out + first);
    return 0;
}
