/* How large a maximal run will be before it runs. Samples: a maximal set of conflict distance
 * s fills a fraction phi_d of space with balls of radius s/2 (random sequential addition's
 * jamming density), so n = phi_d * integral of 1 / V_d(t * coverage * r(x) / 2) dx, more near
 * open faces (the balls reach s/4 past them) and with two radii (a fit: (R_c / R_f)^(d/5)).
 * Cells: the base grid (side t * coverage * r_max / sqrt(d)), or where r is smaller the cells a
 * grid of the local radius would have, times the active cells per base cell runs show. */
#include "estimate.h"
#include "rng.h"
#include <math.h>
#include <string.h>

#define PROBES 4096
#define BATCH 64
#define PROBE_SEED UINT64_C(0x5eed0f0e57a11a7e)

/* phi_d: d = 1 Renyi's constant, 2..6 Torquato, Uche and Stillinger (2006), 7 and 8 their fit;
 * past 8D the 8D/7D ratio per axis (the same table as the Python binding's JAMMING_DENSITY). */
static double jamming_density(int d)
{
    static const double phi[9] = {0, 0.7476, 0.5470, 0.3841, 0.2600, 0.1707, 0.1093, 0.0683, 0.0424};
    return d <= 8 ? phi[d] : phi[8] * pow(0.6, d - 8);
}

/* Most active cells per base cell, measured with vpds_stats.peak_active_cells on uniform runs
 * of 10^3-10^5 samples (2D: level 0 counted whole); past 8D doubled per axis. From version 12
 * on, pairs of disks drop cells from 6D (pencil.h): 2.8-5.9 in 6D, 4.5-12.2 in 7D, where
 * version 11 held up to 11 and 20. */
static double cells_per_base_cell(int d, unsigned algorithm)
{
    static const double c[9] = {0, 1, 1, 1.5, 4, 10, 11, 20, 32};
    if (algorithm >= 12 && d == 6) return 6;
    if (algorithm >= 12 && d == 7) return 10;
    return d <= 8 ? c[d] : c[8] * pow(2, d - 8);
}

/* Bytes per active cell and per 64-bit word of its bit-packed coordinates (the level's cells
 * and the part of the next level's a sweep holds with them: it gives back the room of those it
 * has read through realloc, cells.h; an allocator without realloc gets none back, and a sweep
 * holds both levels whole), and per sample (coordinates, r, t, flags, kd-tree and grid
 * entries): fits of peak_bytes over 1D-11D runs. A cell whose coordinates fit 32 bits takes
 * half a word (cells.c). */
#define BYTES_PER_CELL_WORD 12.0
#define BYTES_PER_CELL_WORD_HELD 16.0

/* Bytes per active cell on the base grid of cells of side `side` over the box: its coordinates
 * at level 2, where runs hold the most cells, in 32 bits or in 64-bit words; kept as families
 * (cells.h), a record per parent shared by its children (measured at level 2 with algorithm
 * version 12: 2.6 in 3D, 3.7 in 4D, 5.5 in 5D, 7.5 in 6D, 11.6 in 7D, 22 in 8D, about
 * 0.9 2^(d/2)), and a bucket entry of 9 bytes per 64 cells. */
static double bytes_per_cell(const vpdsi_problem *pb, double side, int gives_back)
{
    double bits = 0, word = gives_back ? BYTES_PER_CELL_WORD : BYTES_PER_CELL_WORD_HELD;
    int k;
    for (k = 0; k < pb->dim; k++) /* cells.c's layout: the bits of n0, plus one per level */
        bits += vpdsi_bit_length((uint64_t)ceil((pb->hi[k] - pb->lo[k]) / side)) + 2;
    if (!vpdsi_cells_families_serve(pb->dim, pb->two_radii))
        return bits <= 32 ? word / 2 : word * ceil(bits / 64);
    bits -= pb->dim; /* the parents' level */
    return word / 8 *
           (vpdsi_cells_family_bytes(pb->dim, (unsigned)bits) / (0.9 * pow(2, pb->dim / 2.0)) + 9.0 / 64);
}

static double bytes_per_sample(int d)
{
    static const double b[6] = {0, 32, 52, 131, 206, 311};
    return d <= 5 ? b[d] : 64.0 * d;
}

/* The background grid of a constant radius (mps.c's choose_index), one int32 per cell of the
 * base grid and of its border. The fits above hold it in 1D-3D (measured with it); from 4D on
 * they were measured with the kd-tree, and in 5D the border alone can be most of the peak
 * (r = 0.4: 6^5 base cells, 12^5 with the border). */
static double grid_bytes(const vpdsi_problem *pb, const vpdsi_store *st, double t, double side)
{
    double n[VPDS_MAX_DIM], sides[VPDS_MAX_DIM];
    int k;
    if (pb->dim < 4 ||
        !vpdsi_bgrid_serves(pb->dim, st->sizing.kind == VPDSI_SIZING_CONSTANT, pb->two_radii,
                            pb->any_periodic))
        return 0;
    for (k = 0; k < pb->dim; k++) { /* as mps.c lays out the base grid */
        double ext = pb->hi[k] - pb->lo[k], cells = ceil(ext / side);
        n[k] = cells < 1 ? 1 : cells;
        sides[k] = ext / n[k];
    }
    return sizeof(int32_t) * vpdsi_bgrid_cells(pb->dim, n, sides, t * pb->inhibition * st->sizing.radius);
}

typedef struct probe_sums {
    double inv_ball, inv_cell; /* sums of 1 / V(t R_c / 2) and of 1 / side(r)^d */
    unsigned inside;
} probe_sums;

/* BATCH probes: r and the domain through the store (their errors said in its sink). */
static vpds_status probe_batch(const vpdsi_problem *pb, vpdsi_store *st, vpdsi_domain *dm,
                               double t, double ball, vpdsi_rng *rng, probe_sums *sums)
{
    double x[BATCH * VPDS_MAX_DIM], r[BATCH], phi[BATCH], root_d = sqrt((double)pb->dim);
    int d = pb->dim, k;
    size_t i;
    vpds_status e;
    for (i = 0; i < BATCH; i++) {
        for (k = 0; k < d; k++)
            x[i * (size_t)d + (size_t)k] = pb->lo[k] + (pb->hi[k] - pb->lo[k]) * vpdsi_rng_unit(rng);
        phi[i] = 0;
        if (dm->fn && (e = vpdsi_domain_at(dm, st, x + i * (size_t)d, &phi[i])) != VPDS_OK) return e;
    }
    if ((e = vpdsi_store_radii(st, x, BATCH, r)) != VPDS_OK) return e;
    for (i = 0; i < BATCH; i++) {
        if (phi[i] > 0) continue;
        sums->inside++;
        sums->inv_ball += 1 / (ball * pow(0.5 * t * pb->coverage * r[i], d));
        sums->inv_cell += pow(root_d / (t * pb->coverage * r[i]), d);
    }
    return VPDS_OK;
}

/* Samples near an open face: their balls of radius s/2 reach about s/4 past it, as if each
 * open axis were longer by s/2; s is the typical reach, (mean of 1/side^d)^(-1/d) sqrt(d). */
static double face_factor(const vpdsi_problem *pb, double inv_cell_sum)
{
    double factor = 1, reach;
    int k;
    if (!(inv_cell_sum > 0)) return 1;
    reach = sqrt((double)pb->dim) * pow(inv_cell_sum / PROBES, -1.0 / pb->dim);
    for (k = 0; k < pb->dim; k++)
        if (pb->period[k] == 0) factor *= 1 + reach / (2 * (pb->hi[k] - pb->lo[k]));
    return factor;
}

vpds_status vpdsi_estimate_run(const vpdsi_problem *pb, vpdsi_store *st, vpdsi_domain *dm,
                               double t, size_t fixed_bytes, vpds_run_estimate *out)
{
    probe_sums sums;
    vpdsi_rng rng;
    double volume = 1, side, base, fraction, cells;
    double ball = pow(3.14159265358979323846, pb->dim / 2.0) / tgamma(pb->dim / 2.0 + 1);
    int d = pb->dim, k, b;
    vpds_status e;
    memset(out, 0, sizeof *out);
    memset(&sums, 0, sizeof sums);
    vpdsi_rng_seed(&rng, PROBE_SEED);
    for (b = 0; b < PROBES / BATCH; b++)
        if ((e = probe_batch(pb, st, dm, t, ball, &rng, &sums)) != VPDS_OK) return e;
    for (k = 0; k < d; k++) volume *= pb->hi[k] - pb->lo[k];
    side = vpdsi_lattice_base_side(t * pb->coverage * st->sizing.rmax, d);
    base = vpdsi_lattice_base_count(d, pb->lo, pb->hi, side);
    /* a domain no probe meets still has its straddling cells: count one probe's share */
    fraction = (sums.inside > 0 ? sums.inside : 1) / (double)PROBES;
    cells = volume * sums.inv_cell / PROBES;
    if (cells < base * fraction) cells = base * fraction;
    out->samples = jamming_density(d) * volume * sums.inv_ball / PROBES *
                   pow(pb->coverage / pb->inhibition, d / 5.0) * face_factor(pb, sums.inv_cell);
    out->base_cells = base;
    out->cells = cells_per_base_cell(d, pb->algorithm) * cells;
    out->bytes = bytes_per_cell(pb, side, st->mem->a.realloc != NULL) * out->cells +
                 bytes_per_sample(d) * out->samples;
    /* two radii keep the index of the uncovered region, a domain the cells along its boundary:
     * about as much again each, measured */
    if (pb->two_radii) out->bytes *= 2;
    if (dm->fn) out->bytes *= 2;
    out->bytes += grid_bytes(pb, st, t, side);
    out->bytes += (double)fixed_bytes;
    return VPDS_OK;
}
