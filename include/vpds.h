/*
 * libvpds: maximal Poisson-disk sampling with spatially varying radii, in any dimension.
 *
 * Implements "Variable Radii Poisson-Disk Sampling" (Mitchell, Ebeida et al.): Algorithm 1 with
 * the four distance rules of Section 5, decoupled inhibition/coverage radii (Section 3) and
 * hierarchical refinement (Section 4).
 *
 * Definitions used throughout (scale t, rule f, sizing r):
 *   a point y CONFLICTS with sample x_i when |y - x_i| <  t * inhibition * f(x_i, y)
 *   a point y is COVERED by sample x_i when |y - x_i| <= t * coverage   * f(x_i, y)
 *   f(x, y) = r(x) (prior), r(y) (current), max(r(x), r(y)) (bigger), min(r(x), r(y)) (smaller).
 * A run ends with every sample free of conflict with the samples before it (insertion order)
 * and every point of the box covered, up to the precision reported in vpds_stats.delta.
 *
 * Usage: fill a descriptor from vpds_default_desc(), change what you need, vpds_create(),
 * vpds_run(), read vpds_points()/vpds_count(), vpds_destroy(). No global state: one sampler per
 * thread needs no locks. The library never prints, exits or aborts.
 */
#ifndef VPDS_H
#define VPDS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && defined(VPDS_BUILD_SHARED)
#define VPDS_API __declspec(dllexport)
#elif defined(_WIN32) && defined(VPDS_SHARED)
#define VPDS_API __declspec(dllimport)
#elif defined(__GNUC__)
#define VPDS_API __attribute__((visibility("default")))
#else
#define VPDS_API
#endif

#define VPDS_VERSION_MAJOR 1
#define VPDS_VERSION_MINOR 0
#define VPDS_VERSION_PATCH 0
/* The points a seed gives are fixed for one algorithm version; pin it in vpds_desc to keep them.
 * 1: 1.0.0. 2: the two-radii and domain coverage search drops what it used to keep only for
 * want of precision (same guarantees; other points with two radii or a domain). 3: a stream
 * continued after a run splits its regions down to the run's scale before searching them
 * (versions 1-2 searched the whole box at once and could give up with VPDS_ERR_DOMAIN; other
 * points for vpds_next after vpds_run). 4: with two radii the coverage search keeps what it
 * learns (cells shown covered, witness points) and a dart asks only about the cells near it;
 * the points of version 3 except where the search's box budget or precision decided. 5: with a
 * constant radius and no domain (dim <= 4) the stream finds the largest gap exactly, at a vertex
 * of the bisectors of the few samples near it, instead of to the tolerance, and a search to the
 * tolerance (a variable radius, a domain) keeps its open boxes in a heap, which splits them in
 * another order where bounds tie (other points for vpds_next; the runs give the points of
 * version 4). 6: with two radii each cell a dart asks about keeps which of its sub-boxes its
 * searches showed covered, later questions and the sweep skip them, and a search visits a box's
 * children from the one farthest from the dart (other points with two radii, where the search's
 * box budget decided). 7: the stream on a mesh (vpds_mesh_next) splits a piece in two at its
 * longest edge instead of in four at its edges' midpoints, so that a needle's pieces get shorter
 * without getting thinner, and with a constant radius it inserts the exact farthest point (from
 * the few samples near a small piece) instead of one within the tolerance (other points for
 * vpds_mesh_next), and a sizing callback's largest radius is estimated from at most 4096
 * probes in any dimension, not 3^d (other points for a sizing callback in 8 dimensions and up;
 * every other box gives the points of version 6). 8: the coverage search of two radii and of a
 * domain, before splitting a box whose nearest point is covered, tests the box's corner
 * farthest from the sample that covers it, so that it stops at an uncovered wedge at the edge
 * of a cell instead of splitting down to its precision limit (the points of version 7 except
 * where the search's box budget or precision decided; fewer boxes and sizing calls), and the
 * stream's search to the tolerance (a variable radius, a domain) finds the nearest samples of a
 * split's children in a list its parent's split made, filtered, not in the kd-tree (the same
 * minimum; the first of equally near samples may differ: the points of version 7 on every
 * golden configuration). 9: the stream's exact farthest point (one radius, no domain) in 5D to
 * 7D too, where version 8 searched to the tolerance (other points for vpds_next in 5D to 7D;
 * everything else gives the points of version 8). 10: the stream's farthest point in 2D (one
 * radius, no domain, open axes) is read from the Voronoi diagram of the samples, kept as a
 * Delaunay triangulation that each sample changes only around itself, where version 9
 * searched regions of the box: the same largest gaps to round-off, other bits, and where two
 * points are equally far another may come first (other points for vpds_next in 2D; everything
 * else gives the points of version 9). 11: the same in 3D, from the Delaunay tetrahedralisation
 * and, along the box's edges, the lower envelope of the samples' distances (other points for
 * vpds_next in 3D; everything else gives the points of version 10). 12: from 6D on, the sweep
 * of Algorithm 1 also drops a cell that two disks hold together though neither holds it alone
 * (the ball of their pencil centred on their radical hyperplane, which lies in their union),
 * so fewer cells split into 2^d children and fewer darts land where nothing is left (other
 * points for a run or refinement in 6D and up), and up to 5D the coverage search of two radii
 * and of a domain drops such a box too (the points of 11 except where the search's box budget
 * decided; everything else gives the points of 11). 13: in 1-4D the stream's search with a
 * domain also tries, for a box whose centre lies outside the domain, the box's corners that lie
 * in it, so that a domain meeting boxes only along their faces (a boundary on a plane the search
 * splits at: x <= 0.5, an axis-aligned square, a mask of 2^k cells) is found there; 12 found no
 * point along such a boundary and vpds_next gave up with VPDS_ERR_DOMAIN (other points for
 * vpds_next with a domain; everything else gives the points of 12). */
#define VPDS_ALGORITHM_VERSION 13
/* Largest supported dimension; a larger dim is refused by vpds_create. */
#define VPDS_MAX_DIM 16
/* Relative tolerance eps of the continuous stream (vpds_next): each t it reports is an upper
 * bound of the scale at which the earlier samples stop being maximal, and the point inserted
 * there is within t * (1 - eps) * inhibition * f of them at worst (exact with two radii when
 * inhibition <= coverage * (1 - eps)); where a maximum flat over a wide area made a search go
 * on at VPDS_STREAM_DOMAIN_TOLERANCE, vpds_stats.stream_slack says so. */
#define VPDS_STREAM_TOLERANCE 1e-5
/* The same with a domain (desc.domain set): on a curved boundary the maximum of the gap is flat
 * along the boundary, and a tolerance eps costs about 1/eps search boxes per sample there. */
#define VPDS_STREAM_DOMAIN_TOLERANCE 1e-3
/* Value of vpds_desc.lipschitz meaning "not given". */
#define VPDS_UNSET (-1.0)

/* Status codes: 0 is success, positive values are non-error outcomes, negative are errors. */
typedef enum vpds_status {
    VPDS_OK = 0,
    VPDS_PAUSED = 1,      /* a budget or the progress callback stopped the run: call it again */
    VPDS_STREAM_END = 2,  /* vpds_next: the next event lies at or below t_min; nothing consumed */
    VPDS_ERR_INVALID_ARGUMENT = -1, /* an argument or descriptor field is out of range */
    VPDS_ERR_BAD_DESCRIPTOR = -2,   /* not from vpds_default_desc(), or a layout not known */
    VPDS_ERR_OUT_OF_MEMORY = -3,    /* the allocator returned NULL; the sampler is unchanged */
    VPDS_ERR_UNSUPPORTED = -4,      /* a capability this version does not provide */
    VPDS_ERR_SIZING = -5,           /* the sizing function returned NaN, Inf, zero or < 0 */
    VPDS_ERR_LIPSCHITZ = -6,        /* the sizing function was seen to break the declared L */
    VPDS_ERR_STATE = -7,            /* the call is not valid in the sampler's current state */
    VPDS_ERR_OVERFLOW = -8,         /* the request would overflow a size computation */
    VPDS_ERR_DOMAIN = -9            /* the domain function returned NaN, broke 1-Lipschitz, or
                                       its domain holds no point the sampler can reach */
} vpds_status;

/* The distance function f of Section 5 (Table 1). */
typedef enum vpds_rule {
    VPDS_RULE_DEFAULT = 0, /* = VPDS_RULE_SMALLER, the paper's recommendation */
    VPDS_RULE_PRIOR = 1,   /* f = r(x_i); needs L < 1/2 */
    VPDS_RULE_CURRENT = 2, /* f = r(y); needs L < 1 */
    VPDS_RULE_BIGGER = 3,  /* f = max(r(x_i), r(y)); needs L < 1/2 */
    VPDS_RULE_SMALLER = 4  /* f = min(r(x_i), r(y)); needs L < 1 */
} vpds_rule;

/* Memory comes from here. alloc and free are both set or both NULL (NULL: malloc/free).
 * realloc is optional (NULL: alloc, copy, free); it must keep the contents like C's realloc. */
typedef struct vpds_allocator {
    void *(*alloc)(size_t size, void *user);
    void *(*realloc)(void *ptr, size_t old_size, size_t new_size, void *user);
    void (*free)(void *ptr, size_t size, void *user);
    void *user;
} vpds_allocator;

/* r(x) > 0 at a point x of dim coordinates. */
typedef double (*vpds_sizing_fn)(const double *x, void *user);
/* r at n points (x holds n*dim doubles); write n radii to r_out; return 0, or non-zero to fail.
 * A failure stops the call at once with VPDS_ERR_SIZING (r_out is not read), leaving the sampler
 * as a pause would: calling again gives the points of a run that never failed. A binding whose
 * callback raised (Ctrl-C in Python) returns non-zero and reports its exception after the call. */
typedef int (*vpds_sizing_batch_fn)(const double *x, size_t n, double *r_out, void *user);
/* Signed distance to the domain's boundary, negative inside (a point with 0 is inside too),
 * 1-Lipschitz; +INFINITY is allowed far outside. The domain is box ∩ {x : domain(x) <= 0}.
 * NaN is a failure: the call stops with VPDS_ERR_DOMAIN, as a sizing_batch failure does. */
typedef double (*vpds_domain_fn)(const double *x, void *user);

/* Passed to the progress callback between chunks of work. */
typedef struct vpds_progress {
    uint64_t darts;          /* darts thrown so far in this sampler */
    size_t samples;          /* samples held (fixed points included) */
    uint64_t active_cells;   /* cells still active at the current level */
    uint32_t level;          /* current level of the flat hyper-octree */
    double t;                /* scale being sampled */
} vpds_progress;
/* Return 0 to go on, non-zero to pause (the call then returns VPDS_PAUSED). */
typedef int (*vpds_progress_fn)(const vpds_progress *progress, void *user);

/* A regular grid of radii with multilinear interpolation (see vpds_grid_create). */
typedef struct vpds_grid vpds_grid;

/* The sampler's descriptor. Always start from vpds_default_desc(): the cookie and size in the
 * first two fields let the library refuse a struct that did not come from it. */
typedef struct vpds_desc {
    uint32_t cookie;      /* set by vpds_default_desc; do not change */
    uint32_t struct_size; /* set by vpds_default_desc; do not change */

    int dim;              /* 1..VPDS_MAX_DIM (default 2) */
    const double *lo;     /* dim doubles: the box's lower corner (NULL: all 0) */
    const double *hi;     /* dim doubles: the box's upper corner (NULL: all 1) */
    const int *periodic;  /* dim ints, non-zero for a toroidal axis (NULL: none) */

    /* Radius: constant `radius` unless a sizing function is given (callback, batch or grid). */
    double radius;                     /* default 0.05 */
    vpds_sizing_fn sizing;
    vpds_sizing_batch_fn sizing_batch; /* optional faster form of sizing; used when set */
    void *sizing_user;
    const vpds_grid *sizing_grid;      /* copied at vpds_create; its L is computed */
    double lipschitz;   /* L of r; VPDS_UNSET by default; required with a callback */
    double radius_min;  /* optional lower bound of r (0: unknown); needed by `weighted` + callback */
    double radius_max;  /* optional upper bound of r (0: derived from L and the box) */
    vpds_rule rule;

    double inhibition;  /* R_f factor (default 1) */
    double coverage;    /* R_c factor (default 1), inhibition <= coverage */
    int weighted;       /* non-zero: weighted-bias-free process, density 1/r^d (Eq. 12) */

    vpds_domain_fn domain; /* NULL: the whole box */
    void *domain_user;

    uint64_t seed;
    vpds_allocator allocator;

    uint64_t budget;            /* work units per call before VPDS_PAUSED (0: none): a dart, a
                                   cell (past 8D: each 256 of a split's 2^d children), or a box
                                   of the coverage search (two radii, domains) */
    vpds_progress_fn progress;  /* called between chunks of work; may pause */
    void *progress_user;

    uint32_t algorithm_version; /* 0: current (VPDS_ALGORITHM_VERSION); others are refused */
} vpds_desc;

/* Statistics of everything the sampler has done so far. */
typedef struct vpds_stats {
    uint64_t darts;            /* darts thrown */
    uint64_t accepted;         /* darts that became samples */
    uint32_t levels;           /* deepest level of the hyper-octree reached, plus one */
    uint64_t peak_active_cells;
    size_t bytes_held;         /* bytes currently allocated by the sampler */
    size_t peak_bytes;         /* largest bytes_held seen */
    uint64_t sizing_calls;     /* points at which r was evaluated */
    double delta;              /* largest diagonal of a cell left active by the precision limit
                                  (0: none); the set is then covered at t*coverage*f + delta */
    double t;                  /* current scale */
    int maximal;               /* non-zero when the last run completed */
    uint64_t domain_calls;     /* points at which the domain function was evaluated */
    double stream_slack;       /* the largest t / g(y) - 1 of the stream's events (vpds_next):
                                  each event's farthest point y lies at least t / (1 +
                                  stream_slack) from the samples before it, in scaled distance */
    uint64_t reserved[4];
} vpds_stats;

typedef struct vpds_sampler vpds_sampler;

/* Defaults, cookie and size. */
VPDS_API vpds_desc vpds_default_desc(void);
/* Check a descriptor. Writes why it is refused (field and value) into msg (cap bytes). */
VPDS_API vpds_status vpds_validate(const vpds_desc *desc, char *msg, size_t cap);
VPDS_API vpds_status vpds_create(const vpds_desc *desc, vpds_sampler **out);
VPDS_API void vpds_destroy(vpds_sampler *sampler);

VPDS_API const char *vpds_status_string(vpds_status status);
/* What exactly was wrong in the sampler's last failed call ("" if none). */
VPDS_API const char *vpds_last_error(const vpds_sampler *sampler);
VPDS_API const char *vpds_version_string(void);

/* Sample until maximal at the current scale (1 for a new sampler). */
VPDS_API vpds_status vpds_run(vpds_sampler *sampler);
/* Discrete decrease (Section 4.3) to scale t < current, then maximal there. */
VPDS_API vpds_status vpds_refine(vpds_sampler *sampler, double t);
/* Continuous decrease (Section 4.2): one sample per call, t non-increasing. */
VPDS_API vpds_status vpds_next(vpds_sampler *sampler, double t_min, double *x_out, double *t_out);
/* Up to n events of vpds_next in one call, the same ones n calls give: the samples into x_out
 * (n * dim doubles) and their t into t_out (n), either may be NULL (the samples are held by the
 * sampler in any case: vpds_points); *count says how many were written. Returns VPDS_OK after n
 * events, VPDS_STREAM_END when the next event's t would be at or below t_min, else the error of
 * the event that failed: the events before it stay, as n calls of vpds_next leave them. */
VPDS_API vpds_status vpds_next_n(vpds_sampler *sampler, size_t n, double t_min, double *x_out,
                                 double *t_out, size_t *count);
/* Fixed points (objects already placed): n points of dim doubles; r NULL: the sizing decides. */
VPDS_API vpds_status vpds_add_points(vpds_sampler *sampler, const double *x, const double *r,
                                     size_t n);
/* Change the work budget per call (0: none), e.g. per frame. */
VPDS_API vpds_status vpds_set_budget(vpds_sampler *sampler, uint64_t budget);

VPDS_API size_t vpds_count(const vpds_sampler *sampler);
VPDS_API int vpds_dim(const vpds_sampler *sampler);
/* count*dim doubles in insertion order; valid until the next call that changes the sampler. */
VPDS_API const double *vpds_points(const vpds_sampler *sampler);
/* r at each sample (unscaled). */
VPDS_API const double *vpds_radii(const vpds_sampler *sampler);
/* Scale t at which each sample was inserted (+INFINITY for fixed points). */
VPDS_API const double *vpds_scales(const vpds_sampler *sampler);
/* Per-sample flags: VPDS_FLAG_FIXED for a fixed point, VPDS_FLAG_OWN_RADIUS when its radius was
 * given to vpds_add_points rather than read from the sizing. */
#define VPDS_FLAG_FIXED 1u
#define VPDS_FLAG_OWN_RADIUS 2u
VPDS_API const uint8_t *vpds_flags(const vpds_sampler *sampler);
VPDS_API vpds_stats vpds_get_stats(const vpds_sampler *sampler);

/* ---- Before a run: how large it will be, and a limit on the memory it may take. */
/* An estimate of a maximal run at scale t (not a bound: within a factor of about 2 in 1D-8D,
 * larger errors for small or thin boxes and domains). samples: the jamming density of random
 * sequential addition integrated over the box (and the domain) at the inhibition radius;
 * cells: most active cells at once; bytes: the peak of vpds_stats.peak_bytes, from per-cell and
 * per-sample costs measured in every dimension. A count past what a double holds is +INFINITY. */
typedef struct vpds_run_estimate {
    double samples;
    double base_cells;  /* cells of level 0 (exact for the current r_max) */
    double cells;
    double bytes;
    double reserved[4];
} vpds_run_estimate;
/* Fill *out for a maximal run at scale t (t > 0; 0: the scale vpds_run would sample). A
 * sizing or domain function is called at 4096 fixed points of the box (the samples do not
 * change; vpds_stats' call counts do); a bad value is its usual error. */
VPDS_API vpds_status vpds_estimate(vpds_sampler *sampler, double t, vpds_run_estimate *out);
/* Hold at most `bytes` (0: no limit, the default). A run or refinement whose estimate exceeds
 * the limit is refused before it starts (VPDS_ERR_OUT_OF_MEMORY, the estimate in
 * vpds_last_error); past the estimate, an allocation that would exceed the limit fails as the
 * allocator would, and the sampler is left as after any allocation failure. With a limit, each
 * run from a new scale makes that estimate first (4096 sizing and domain calls). A sizing grid's
 * copy, made at vpds_create, is not counted. */
VPDS_API vpds_status vpds_set_memory_limit(vpds_sampler *sampler, size_t bytes);

/* ---- Grid sizing: values at the nodes of a regular grid over [lo, hi], multilinear between. */
typedef struct vpds_grid_desc {
    uint32_t cookie;
    uint32_t struct_size;
    int dim;
    const size_t *shape;  /* nodes per axis (>= 2 each); values are C order, axis 0 slowest */
    const double *values; /* prod(shape) radii > 0; copied */
    const double *lo;     /* dim doubles (NULL: all 0) */
    const double *hi;     /* dim doubles (NULL: all 1) */
    vpds_allocator allocator;
} vpds_grid_desc;

VPDS_API vpds_grid_desc vpds_default_grid_desc(void);
VPDS_API vpds_status vpds_grid_validate(const vpds_grid_desc *desc, char *msg, size_t cap);
VPDS_API vpds_status vpds_grid_create(const vpds_grid_desc *desc, vpds_grid **out);
VPDS_API void vpds_grid_destroy(vpds_grid *grid);
/* Exact Lipschitz constant of the interpolant: its largest gradient norm (at cell corners). */
VPDS_API double vpds_grid_lipschitz(const vpds_grid *grid);
/* Lower values, as little as the sufficient condition "every edge slope <= L/sqrt(dim)"
 * allows (the largest such function below the grid), so that the interpolant is L-Lipschitz. */
VPDS_API vpds_status vpds_grid_enforce_lipschitz(vpds_grid *grid, double lipschitz);
/* r at x (coordinates outside [lo, hi] are clamped; NaN where a coordinate is NaN). */
VPDS_API double vpds_grid_eval(const vpds_grid *grid, const double *x);
VPDS_API const double *vpds_grid_values(const vpds_grid *grid);
VPDS_API size_t vpds_grid_size(const vpds_grid *grid);

/* ---- Built-in domains: set desc.domain = vpds_polygon_sdf (or vpds_mask_sdf) and
 * desc.domain_user = the object; it must outlive the samplers that use it. A sampler of another
 * dimension than the domain's (2 for a polygon, the mask's axes) is refused by vpds_validate. */

/* A 2D polygon set with holes: rings of vertices, closed implicitly; a point is inside when a
 * ray from it crosses the rings an odd number of times (a ring inside another is a hole). */
typedef struct vpds_polygon vpds_polygon;
typedef struct vpds_polygon_desc {
    uint32_t cookie;
    uint32_t struct_size;
    const double *xy;         /* x0, y0, x1, y1, ... of every ring, one ring after the other */
    const size_t *ring_sizes; /* vertices of each ring (>= 3) */
    size_t n_rings;
    vpds_allocator allocator;
} vpds_polygon_desc;

VPDS_API vpds_polygon_desc vpds_default_polygon_desc(void);
/* Refuses non-finite vertices, repeated consecutive vertices, edges that cross or touch
 * (within a ring or between rings), naming the edges and the point, and a ring that encloses
 * no area at its coordinates' precision (darts could never land in it). */
VPDS_API vpds_status vpds_polygon_validate(const vpds_polygon_desc *desc, char *msg, size_t cap);
VPDS_API vpds_status vpds_polygon_create(const vpds_polygon_desc *desc, vpds_polygon **out);
VPDS_API void vpds_polygon_destroy(vpds_polygon *polygon);
/* Exact signed distance to the rings' edges, negative inside (a vpds_domain_fn; O(edges)). */
VPDS_API double vpds_polygon_sdf(const double *x, void *polygon);

/* A mask over the box: values on a grid of cells (C order, axis 0 slowest); a cell is inside
 * when its value >= threshold. Its domain function is the exact Euclidean distance transform
 * between inside and outside cell centres, halved and interpolated multilinearly, divided by
 * the interpolant's exact Lipschitz constant where that exceeds 1: the boundary lies halfway
 * between inside and outside centres. */
typedef struct vpds_mask vpds_mask;
typedef struct vpds_mask_desc {
    uint32_t cookie;
    uint32_t struct_size;
    int dim;              /* 1..VPDS_MAX_DIM (default 2) */
    const size_t *shape;  /* cells per axis (>= 2 each) */
    const double *values; /* prod(shape) values; copied */
    double threshold;     /* inside: value >= threshold (default 0.5) */
    const double *lo;     /* dim doubles: the box the mask covers (NULL: all 0) */
    const double *hi;     /* (NULL: all 1) */
    vpds_allocator allocator;
} vpds_mask_desc;

VPDS_API vpds_mask_desc vpds_default_mask_desc(void);
/* Refuses NaN values, a non-finite threshold and a mask with no inside cell. */
VPDS_API vpds_status vpds_mask_validate(const vpds_mask_desc *desc, char *msg, size_t cap);
VPDS_API vpds_status vpds_mask_create(const vpds_mask_desc *desc, vpds_mask **out);
VPDS_API void vpds_mask_destroy(vpds_mask *mask);
VPDS_API double vpds_mask_sdf(const double *x, void *mask);

/* ---- Grid windows: a grid too large to hold, read one part at a time (tiled sampling). */
/* desc->shape and desc->values describe nodes [offset[k], offset[k] + shape[k]) of a grid of
 * whole_shape[k] nodes per axis over [desc->lo, desc->hi] (the whole grid's box). Inside the
 * cells it holds, the window evaluates bit for bit as the whole grid; elsewhere vpds_grid_eval
 * gives NaN and a sampler using it stops with VPDS_ERR_SIZING. Its Lipschitz constant, min and
 * max are the window's own; vpds_grid_enforce_lipschitz refuses a window (VPDS_ERR_UNSUPPORTED). */
VPDS_API vpds_status vpds_grid_validate_window(const vpds_grid_desc *desc, const size_t *whole_shape,
                                               const size_t *offset, char *msg, size_t cap);
VPDS_API vpds_status vpds_grid_create_window(const vpds_grid_desc *desc, const size_t *whole_shape,
                                             const size_t *offset, vpds_grid **out);

/* ---- Tiled sampling (libvpds/tiles.c): a box sampled as a grid of tiles, with the guarantees
 * of one run across every seam. Tile k has integer coordinates c (C order: axis 0 slowest) and
 * phase sum_k (c_k & 1) << k: 2^dim phases, and tiles of one phase never touch. A tile's run
 * samples its core (its cell of the grid of tiles) with the seed vpds_tiling_seed(tile) and,
 * as fixed points, the samples of its dependencies (the neighbouring tiles of lower phase,
 * wrapping on periodic axes) that lie within the margin of the core: margin = scale * coverage *
 * r_max, the farthest any conflict or coverage disk reaches. So every sample is checked against
 * every earlier sample that could conflict with it, every point of a core is covered, and tiles
 * of one phase (at least one tile side, >= margin, apart) cannot interact: the union of the
 * cores is conflict-free in the order (phase, tile, insertion) and maximal, and it depends on
 * the seed alone, never on the order in which tiles run. A tile of phase p needs its
 * dependencies done first, and they theirs: vpds_tiling_cone lists that cone in an order that
 * can run, so an engine can sample the tiles around a camera on demand and get the batch's
 * points. Only a tile's own samples (not its fixed points) belong to it. */
typedef struct vpds_tiling vpds_tiling;

typedef struct vpds_tiling_desc {
    uint32_t cookie;          /* set by vpds_default_tiling_desc; do not change */
    uint32_t struct_size;
    const vpds_desc *sampler; /* the whole box and problem (box, periodic, sizing, rule, radii,
                                 seed, allocator, budget); read at create: lo, hi, periodic are
                                 copied and a sizing_grid cloned, callbacks and their user
                                 pointers must outlive the tiling */
    const uint64_t *tiles;    /* dim tile counts (>= 1; even on a periodic axis) */
    double scale;             /* the scale t of every tile's run (default 1) */
    int sizing_per_tile;      /* non-zero: no sizing in `sampler`; each vpds_tile_create gets a
                                 window of the grid (sampler->lipschitz and radius_max, the whole
                                 grid's, are then required; radius_min too if weighted) */
} vpds_tiling_desc;

/* The samples of one dependency: its own samples, in their insertion order. */
typedef struct vpds_tile_points {
    uint64_t tile;
    const double *x; /* n * dim */
    const double *r; /* n radii (vpds_radii) */
    size_t n;
} vpds_tile_points;

/* Most dependencies a tile can have: its 3^dim - 1 neighbours. */
#define VPDS_TILING_MAX_DEPS 6560
/* Largest dim of a tiling (a tile has up to 3^dim - 1 neighbours); larger is VPDS_ERR_UNSUPPORTED. */
#define VPDS_TILING_MAX_DIM 8

VPDS_API vpds_tiling_desc vpds_default_tiling_desc(void);
/* Why a tiling is refused (field and value), into msg. Tiles thinner than the margin are
 * refused: tiles of one phase would interact. */
VPDS_API vpds_status vpds_tiling_validate(const vpds_tiling_desc *desc, char *msg, size_t cap);
VPDS_API vpds_status vpds_tiling_create(const vpds_tiling_desc *desc, vpds_tiling **out);
VPDS_API void vpds_tiling_destroy(vpds_tiling *tiling);
/* Number of tiles (0 for a NULL tiling). */
VPDS_API uint64_t vpds_tiling_count(const vpds_tiling *tiling);
VPDS_API double vpds_tiling_margin(const vpds_tiling *tiling);
/* Phase of a tile (0 .. 2^dim - 1), -1 for a tile out of range. */
VPDS_API int vpds_tiling_phase(const vpds_tiling *tiling, uint64_t tile);
/* The seed of a tile's run: a splitmix64 hash of the sampler's seed and the tile index. */
VPDS_API uint64_t vpds_tiling_seed(const vpds_tiling *tiling, uint64_t tile);
/* Integer coordinates of a tile, and back (coords wrap on periodic axes; out of range on
 * another axis is VPDS_ERR_INVALID_ARGUMENT). */
VPDS_API vpds_status vpds_tiling_coords(const vpds_tiling *tiling, uint64_t tile, uint64_t *coords);
VPDS_API vpds_status vpds_tiling_index(const vpds_tiling *tiling, const int64_t *coords,
                                       uint64_t *tile);
/* The tile's core: dim doubles each. Neighbouring cores share their faces exactly. */
VPDS_API vpds_status vpds_tiling_box(const vpds_tiling *tiling, uint64_t tile, double *lo, double *hi);
/* The tiles whose samples this tile's run needs (neighbours of lower phase), ascending; at most
 * VPDS_TILING_MAX_DEPS. With cap too small, *n is the count needed and VPDS_ERR_OVERFLOW. */
VPDS_API vpds_status vpds_tiling_deps(const vpds_tiling *tiling, uint64_t tile, uint64_t *out,
                                      size_t cap, size_t *n);
/* Every tile this tile needs, directly or not, in an order that can run (by phase, then
 * index); the tile itself is not listed. With cap too small, *n is the count needed and
 * VPDS_ERR_OVERFLOW. */
VPDS_API vpds_status vpds_tiling_cone(const vpds_tiling *tiling, uint64_t tile, uint64_t *out,
                                      size_t cap, size_t *n);
/* A sampler for one tile, ready for vpds_run (and budgets, pauses, vpds_last_error): its box is
 * the core, its seed and scale the tile's, and its first *n_fixed samples are the fixed points
 * taken from `deps` (one entry per tile of vpds_tiling_deps, any order); the samples after them
 * are the tile's own. sizing_window: the tile's window of the grid when the tiling has
 * sizing_per_tile (NULL otherwise); it must cover the core. msg (cap bytes) says why on error. */
VPDS_API vpds_status vpds_tile_create(const vpds_tiling *tiling, uint64_t tile,
                                      const vpds_tile_points *deps, size_t n_deps,
                                      const vpds_grid *sizing_window, vpds_sampler **out,
                                      size_t *n_fixed, char *msg, size_t cap);

/* ---- A whole tiling on several threads (libvpds/parallel.c): every tile run as above, phase
 * after phase, the tiles of a phase side by side. The points are the same bytes for any number
 * of threads and any order in which tasks finish: a tile's run depends on its seed and on its
 * dependencies' samples alone, and those are done in earlier phases. */
/* One task of a phase: run task number `task` of the batch. */
typedef void (*vpds_task_fn)(void *batch, uint64_t task);
/* An engine's job system: call run(batch, i) once for each i in 0..n-1, on any threads and in
 * any order, and return when every call has returned. */
typedef void (*vpds_executor_fn)(vpds_task_fn run, void *batch, uint64_t n, void *user);

typedef struct vpds_tiling_run_desc {
    uint32_t cookie;      /* set by vpds_default_tiling_run_desc; do not change */
    uint32_t struct_size;
    int threads;          /* 0 or 1: the calling thread alone; n > 1: n POSIX threads (the
                             calling one and n - 1 the library starts and joins per phase) */
    vpds_executor_fn executor; /* instead of threads: the caller's job system (NULL: none) */
    void *executor_user;
    int callbacks_thread_safe; /* non-zero: the sizing, domain and progress callbacks may run on
                                  several threads at once; else a tiling with one runs serially */
    int allocator_thread_safe; /* non-zero: the tiling's allocator may be called from several
                                  threads at once; else the library calls it under its own lock */
} vpds_tiling_run_desc;

/* The samples of a tiling run: every tile's own samples, in the order (phase, tile, insertion). */
typedef struct vpds_tiled vpds_tiled;

VPDS_API vpds_tiling_run_desc vpds_default_tiling_run_desc(void);
/* Run every tile (a tiling with sizing_per_tile is refused: its windows come from the caller).
 * On failure (a tile's error, out of memory) nothing is kept and msg (cap bytes) names the
 * first failing tile in (phase, tile) order and why. */
VPDS_API vpds_status vpds_tiling_run(const vpds_tiling *tiling, const vpds_tiling_run_desc *desc,
                                     vpds_tiled **out, char *msg, size_t cap);
VPDS_API void vpds_tiled_destroy(vpds_tiled *tiled);
VPDS_API size_t vpds_tiled_count(const vpds_tiled *tiled);
VPDS_API int vpds_tiled_dim(const vpds_tiled *tiled);
/* count * dim doubles; r at each sample; the tile each belongs to. */
VPDS_API const double *vpds_tiled_points(const vpds_tiled *tiled);
VPDS_API const double *vpds_tiled_radii(const vpds_tiled *tiled);
VPDS_API const uint64_t *vpds_tiled_tiles(const vpds_tiled *tiled);
/* Threads that ran tiles at once: 1 when the run stayed serial (threads <= 1, or a callback not
 * declared thread-safe, or a platform without POSIX threads); with an executor, 0. */
VPDS_API int vpds_tiled_threads(const vpds_tiled *tiled);

/* The same run in steps, for an engine that spreads it over frames (libvpds/tiling_job.c): each
 * step runs at most max_tiles more tiles (0: all that are left), side by side within a phase, and
 * returns VPDS_PAUSED while tiles remain, VPDS_OK once every tile is done. The steps change
 * nothing: the result is the bytes of vpds_tiling_run for any max_tiles, threads or executor.
 * A step that fails (a tile's error, out of memory) says which tile and why in msg; the tiles
 * that succeeded stay done and the next step runs the others again, with the same result. The
 * tiling must outlive the job; destroying a job before its end is allowed (a cancel). */
typedef struct vpds_tiling_job vpds_tiling_job;

VPDS_API vpds_status vpds_tiling_job_create(const vpds_tiling *tiling,
                                            const vpds_tiling_run_desc *desc,
                                            vpds_tiling_job **out, char *msg, size_t cap);
VPDS_API vpds_status vpds_tiling_job_step(vpds_tiling_job *job, uint64_t max_tiles, char *msg,
                                          size_t cap);
/* Tiles done so far (of vpds_tiling_count): the job's progress. */
VPDS_API uint64_t vpds_tiling_job_tiles_done(const vpds_tiling_job *job);
/* Once a step returned VPDS_OK: the samples, as vpds_tiling_run gives them (a new vpds_tiled,
 * freed with vpds_tiled_destroy); before, VPDS_ERR_STATE. */
VPDS_API vpds_status vpds_tiling_job_result(const vpds_tiling_job *job, vpds_tiled **out,
                                            char *msg, size_t cap);
VPDS_API void vpds_tiling_job_destroy(vpds_tiling_job *job);

/* ---- Surfaces (libvpds/mesh.c, libvpds/surface.c): maximal Poisson-disk sampling of a triangle
 * mesh. The sampled set S is the union of the mesh's triangles of positive area; distances are
 * Euclidean in R^3 and a point y of S conflicts with or is covered by a sample exactly as in the
 * box case, under each rule (r(y) read at y: interpolated from vertex_radii over y's triangle, or
 * the sizing at y). A completed run is conflict-free in insertion order and maximal: every point
 * of every triangle of positive area, edges and corners included, is covered (up to the precision
 * vpds_stats.delta, 0 when nothing was left). Each sample is uniform by area over the part of S
 * that is free when it is placed (Algorithm 1: active pieces are sub-triangles split at their
 * edge midpoints into four of equal area; a dart picks a piece with probability proportional to
 * its area, then a uniform point of it).
 * Pieces below 2^-40 of a disk's area split only once nothing larger is active, so a sliver far
 * from everything is covered too. The index is the box of the live triangles' corners.
 * A triangle whose area is below 2^-40 of its longest edge squared is degenerate: it is not part
 * of S, gets no darts and is not checked for coverage (its points lie on a segment; where that is
 * another triangle's edge they are covered there). A mesh of degenerate triangles only is refused.
 * Adding or removing degenerate triangles changes no sample (only the face indices they shift).
 * With vertex_radii, L is checked per triangle (the gradient of r over it, against the rule's
 * limit of Table 1); two sheets close in space with different radii are not checked against each
 * other (conflict and coverage stay exact: r is read at the points themselves). */
typedef struct vpds_mesh vpds_mesh;

typedef struct vpds_mesh_desc {
    uint32_t cookie;            /* set by vpds_default_mesh_desc; do not change */
    uint32_t struct_size;
    const double *vertices;     /* n_vertices * 3 doubles; copied at create */
    size_t n_vertices;
    const uint32_t *triangles;  /* n_triangles * 3 vertex indices; copied at create */
    size_t n_triangles;
    double radius;                     /* default 0.05, when no other sizing is set */
    const double *vertex_radii;        /* n_vertices radii > 0, linear over each triangle (NULL: none) */
    vpds_sizing_fn sizing;             /* r at a point of R^3 (as vpds_desc.sizing with dim 3) */
    vpds_sizing_batch_fn sizing_batch;
    void *sizing_user;
    const vpds_grid *sizing_grid;      /* a 3D grid, copied at create */
    double lipschitz;   /* L of the sizing; VPDS_UNSET by default; required with a callback */
    vpds_rule rule;
    double inhibition;  /* R_f factor (default 1); this version needs inhibition == coverage */
    double coverage;    /* R_c factor (default 1) */
    uint64_t seed;
    vpds_allocator allocator;
    uint64_t budget;            /* work units per call before VPDS_PAUSED (0: none): a dart, a piece */
    vpds_progress_fn progress;  /* called between chunks of work; may pause */
    void *progress_user;
    uint32_t algorithm_version; /* 0: current; meshes exist from version 3 on */
} vpds_mesh_desc;

VPDS_API vpds_mesh_desc vpds_default_mesh_desc(void);
/* Why a mesh descriptor is refused (the field, and the vertex or triangle), into msg. */
VPDS_API vpds_status vpds_mesh_validate(const vpds_mesh_desc *desc, char *msg, size_t cap);
VPDS_API vpds_status vpds_mesh_create(const vpds_mesh_desc *desc, vpds_mesh **out);
VPDS_API void vpds_mesh_destroy(vpds_mesh *mesh);
VPDS_API const char *vpds_mesh_last_error(const vpds_mesh *mesh);
/* Sample to maximal at scale 1 (VPDS_OK), or VPDS_PAUSED by the budget or progress: call again.
 * An error (out of memory, a bad sizing value) leaves the mesh as a pause would. */
VPDS_API vpds_status vpds_mesh_run(vpds_mesh *mesh);
/* Continue a completed run down to the smaller scale t (0 < t < the current one): the samples
 * kept, new ones added until maximal at t (Section 4.1). Before any run, the first run's scale
 * (any t > 0); t equal to the current scale continues it (nothing to do once complete). A scale
 * refused for its size (VPDS_ERR_OVERFLOW) leaves the mesh as it was. */
VPDS_API vpds_status vpds_mesh_refine(vpds_mesh *mesh, double t);
/* The continuous stream on the surface (exactly n points: call it n times): the point farthest
 * from the samples in the rule's scaled distance, found by branch and bound, with its scale t
 * (+INFINITY for the first sample, uniform by area). Each prefix {x_k : t_k >= t} covers the
 * surface at t * coverage and keeps conflict-free at t * inhibition * (1 - VPDS_STREAM_TOLERANCE);
 * with a constant radius (algorithm version 7 on) each sample is the exact farthest point, so
 * conflict-free at t * inhibition up to round-off.
 * VPDS_STREAM_END: the next sample's t would be at or below t_min (nothing consumed). From an
 * empty mesh sampler or a completed run (its t caps the scales; a paused run: VPDS_ERR_STATE);
 * each event leaves the samples maximal at its t, so vpds_mesh_run then has nothing to add and
 * vpds_mesh_refine goes below it. x_out: 3 doubles; face and barycentrics through
 * vpds_mesh_faces/_barycentrics. */
VPDS_API vpds_status vpds_mesh_next(vpds_mesh *mesh, double t_min, double *x_out, double *t_out);
/* Up to n events of vpds_mesh_next in one call, as vpds_next_n: x_out 3 * n doubles, t_out n,
 * either may be NULL; *count written; the events before a failing one stay. */
VPDS_API vpds_status vpds_mesh_next_n(vpds_mesh *mesh, size_t n, double t_min, double *x_out,
                                      double *t_out, size_t *count);
VPDS_API vpds_status vpds_mesh_set_budget(vpds_mesh *mesh, uint64_t budget);
VPDS_API size_t vpds_mesh_count(const vpds_mesh *mesh);
/* count * 3 coordinates; r; the scale t each sample was placed at. */
VPDS_API const double *vpds_mesh_points(const vpds_mesh *mesh);
VPDS_API const double *vpds_mesh_radii(const vpds_mesh *mesh);
VPDS_API const double *vpds_mesh_scales(const vpds_mesh *mesh);
/* The triangle of each sample (an index into desc.triangles), and its barycentric coordinates:
 * count * 3 doubles (b0, b1, b2) summing to 1, for the triangle's vertices in order. */
VPDS_API const uint32_t *vpds_mesh_faces(const vpds_mesh *mesh);
VPDS_API const double *vpds_mesh_barycentrics(const vpds_mesh *mesh);
/* Counters as for a box (active_cells count pieces); maximal when the last run completed. */
VPDS_API vpds_stats vpds_mesh_get_stats(const vpds_mesh *mesh);

#ifdef __cplusplus
}
#endif
#endif /* VPDS_H */
