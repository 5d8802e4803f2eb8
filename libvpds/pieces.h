/* Pieces of a triangle mesh: sub-triangles of the lattice that a seed cut into m x m and then
 * midpoint splits make (each split gives four similar children of equal area), their corners,
 * sizes and the bounds of r over them. Shared by Algorithm 1 (surface.c) and the stream on a
 * surface (surface_stream.c); reads the store only for r at a point. */
#ifndef VPDS_PIECES_H
#define VPDS_PIECES_H
#include "rng.h"
#include "store.h"

/* The mesh as the algorithm reads it (owned by the entry point): only the triangles of positive
 * area, "live", take part. */
typedef struct vpdsi_trimesh {
    const double *v;          /* vertices, 3 doubles each */
    const uint32_t *tri;      /* 3 vertex indices per triangle */
    const double *vr;         /* per-vertex radii (NULL: the store's sizing) */
    size_t n_vertices;
    const uint32_t *live;     /* the triangles with area, ascending */
    const double *area;       /* per live triangle */
    const double *longest;    /* per live triangle: its longest edge */
    size_t n_live;
    double min_edge;          /* 2^-44 of the coordinates' magnitude: no piece splits below */
} vpdsi_trimesh;

/* A piece: lattice triangle (i, j) of live triangle `tri` cut into m x m seed pieces (m of the
 * triangle, chosen per scale so that a seed piece lies within one disk) and split `level` times
 * more, pointing up (corners (i,j), (i+1,j), (i,j+1) in units of 1 / (m 2^level) along its two
 * edges) or down (corners (i+1,j), (i,j+1), (i+1,j+1)). */
typedef struct vpdsi_piece {
    uint64_t i, j;
    uint32_t tri;
    uint8_t level, down;
    uint16_t pad;
} vpdsi_piece;

/* What a surface sample carries besides the store's point, r and t: its triangle and
 * barycentric coordinates, one entry per sample of the store. */
typedef struct vpdsi_surface_marks {
    uint32_t *face; size_t cap_face;     /* the triangle (index into tri) */
    double *bary; size_t cap_bary;       /* 3 barycentric coordinates */
} vpdsi_surface_marks;

void vpdsi_marks_release(vpdsi_surface_marks *mk, vpdsi_mem *m);
/* Room for `more` samples in the store and the marks; nothing changes on failure. */
vpds_status vpdsi_marks_reserve(vpdsi_surface_marks *mk, vpdsi_store *st, size_t more);
/* Append the point x of live triangle k at parameters uv with radius r and scale t (after a
 * reserve). */
void vpdsi_marks_append(vpdsi_surface_marks *mk, vpdsi_store *st, const vpdsi_trimesh *mesh,
                        uint32_t k, const double *uv, const double *x, double r, double t);

/* What one call of a surface algorithm reads and writes (Algorithm 1, the stream: the stream
 * has no budget or progress), and the problem's constants. */
typedef struct vpdsi_surface_ctx {
    const vpdsi_trimesh *mesh;
    vpdsi_store *st;
    vpdsi_surface_marks *marks;
    vpdsi_rng *rng;
    vpds_stats *stats;
    vpds_rule rule;           /* resolved */
    double coverage;          /* = inhibition */
    uint64_t budget;
    vpds_progress_fn progress;
    void *progress_user;
} vpdsi_surface_ctx;

/* Corners of a piece (of a triangle cut into m x m seeds): parameters uv and positions x. */
void vpdsi_piece_corners(const vpdsi_trimesh *mesh, uint64_t m, const vpdsi_piece *p,
                         double uv[3][2], double x[3][3]);
/* Child q (0..3) of a piece: the midpoint split of Section 6's cells carried to triangles. */
vpdsi_piece vpdsi_piece_child(const vpdsi_piece *p, int q);
double vpdsi_piece_area(const vpdsi_trimesh *mesh, uint64_t m, const vpdsi_piece *p);
/* Its longest edge (pieces keep their triangle's shape). */
double vpdsi_piece_edge(const vpdsi_trimesh *mesh, uint64_t m, const vpdsi_piece *p);
/* Bits of m: a piece at level l of lattice m has coordinates below m 2^l. */
unsigned vpdsi_lattice_bits(uint64_t m);
/* The point of live triangle k at parameters uv. */
void vpdsi_trimesh_point(const vpdsi_trimesh *mesh, uint32_t k, const double *uv, double *x);
/* r at a point of live triangle k (parameters uv, position x): vertex radii interpolated, or the
 * store's sizing. */
vpds_status vpdsi_trimesh_radius(const vpdsi_trimesh *mesh, vpdsi_store *st, uint32_t k,
                                 const double *uv, const double *x, double *r);
/* Bounds of r over a piece of live triangle tri (corners uv, x): exact at the corners for
 * vertex radii (r is linear there), the constant, or r at the centroid widened by L times the
 * farthest corner. */
vpds_status vpdsi_piece_bounds(const vpdsi_trimesh *mesh, vpdsi_store *st, uint32_t tri,
                               double uv[3][2], double x[3][3], double *r_lo, double *r_hi);
#endif
