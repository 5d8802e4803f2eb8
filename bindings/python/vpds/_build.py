"""cffi build script: compiles libvpds's C sources into the extension module vpds._vpds.

The declarations below mirror include/vpds.h; in API mode cffi checks them against the real
header when it compiles, so a drift is a build error, not a crash."""
from pathlib import Path

from cffi import FFI

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent.parent  # bindings/python/vpds -> repository root
# The library's sources are compiled into the extension as one translation unit (their static
# names do not clash): setuptools would refuse them as sources outside this directory.
UNITY = "\n".join(f'#include "{p.name}"' for p in sorted((ROOT / "libvpds").glob("*.c")))

ffibuilder = FFI()
ffibuilder.cdef(
    """
typedef enum vpds_status {
    VPDS_OK = 0, VPDS_PAUSED = 1, VPDS_STREAM_END = 2,
    VPDS_ERR_INVALID_ARGUMENT = -1, VPDS_ERR_BAD_DESCRIPTOR = -2, VPDS_ERR_OUT_OF_MEMORY = -3,
    VPDS_ERR_UNSUPPORTED = -4, VPDS_ERR_SIZING = -5, VPDS_ERR_LIPSCHITZ = -6,
    VPDS_ERR_STATE = -7, VPDS_ERR_OVERFLOW = -8
} vpds_status;
typedef enum vpds_rule {
    VPDS_RULE_DEFAULT = 0, VPDS_RULE_PRIOR = 1, VPDS_RULE_CURRENT = 2, VPDS_RULE_BIGGER = 3,
    VPDS_RULE_SMALLER = 4
} vpds_rule;
typedef struct vpds_allocator {
    void *(*alloc)(size_t size, void *user);
    void *(*realloc)(void *ptr, size_t old_size, size_t new_size, void *user);
    void (*free)(void *ptr, size_t size, void *user);
    void *user;
} vpds_allocator;
typedef double (*vpds_sizing_fn)(const double *x, void *user);
typedef int (*vpds_sizing_batch_fn)(const double *x, size_t n, double *r_out, void *user);
typedef double (*vpds_domain_fn)(const double *x, void *user);
typedef struct vpds_progress {
    uint64_t darts; size_t samples; uint64_t active_cells; uint32_t level; double t;
} vpds_progress;
typedef int (*vpds_progress_fn)(const vpds_progress *progress, void *user);
typedef struct vpds_grid vpds_grid;
typedef struct vpds_desc {
    uint32_t cookie; uint32_t struct_size;
    int dim; const double *lo; const double *hi; const int *periodic;
    double radius; vpds_sizing_fn sizing; vpds_sizing_batch_fn sizing_batch; void *sizing_user;
    const vpds_grid *sizing_grid; double lipschitz; double radius_min; double radius_max;
    vpds_rule rule; double inhibition; double coverage; int weighted;
    vpds_domain_fn domain; void *domain_user;
    uint64_t seed; vpds_allocator allocator;
    uint64_t budget; vpds_progress_fn progress; void *progress_user;
    uint32_t algorithm_version;
} vpds_desc;
typedef struct vpds_stats {
    uint64_t darts; uint64_t accepted; uint32_t levels; uint64_t peak_active_cells;
    size_t bytes_held; size_t peak_bytes; uint64_t sizing_calls; double delta; double t;
    int maximal; uint64_t reserved[6];
} vpds_stats;
typedef struct vpds_sampler vpds_sampler;
typedef struct vpds_grid_desc {
    uint32_t cookie; uint32_t struct_size; int dim; const size_t *shape; const double *values;
    const double *lo; const double *hi; vpds_allocator allocator;
} vpds_grid_desc;

vpds_desc vpds_default_desc(void);
vpds_status vpds_validate(const vpds_desc *desc, char *msg, size_t cap);
vpds_status vpds_create(const vpds_desc *desc, vpds_sampler **out);
void vpds_destroy(vpds_sampler *sampler);
const char *vpds_status_string(vpds_status status);
const char *vpds_last_error(const vpds_sampler *sampler);
const char *vpds_version_string(void);
vpds_status vpds_run(vpds_sampler *sampler);
vpds_status vpds_refine(vpds_sampler *sampler, double t);
vpds_status vpds_next(vpds_sampler *sampler, double t_min, double *x_out, double *t_out);
vpds_status vpds_add_points(vpds_sampler *sampler, const double *x, const double *r, size_t n);
vpds_status vpds_set_budget(vpds_sampler *sampler, uint64_t budget);
size_t vpds_count(const vpds_sampler *sampler);
int vpds_dim(const vpds_sampler *sampler);
const double *vpds_points(const vpds_sampler *sampler);
const double *vpds_radii(const vpds_sampler *sampler);
const double *vpds_scales(const vpds_sampler *sampler);
const uint8_t *vpds_flags(const vpds_sampler *sampler);
vpds_stats vpds_get_stats(const vpds_sampler *sampler);

vpds_grid_desc vpds_default_grid_desc(void);
vpds_status vpds_grid_validate(const vpds_grid_desc *desc, char *msg, size_t cap);
vpds_status vpds_grid_create(const vpds_grid_desc *desc, vpds_grid **out);
void vpds_grid_destroy(vpds_grid *grid);
double vpds_grid_lipschitz(const vpds_grid *grid);
vpds_status vpds_grid_enforce_lipschitz(vpds_grid *grid, double lipschitz);
double vpds_grid_eval(const vpds_grid *grid, const double *x);
const double *vpds_grid_values(const vpds_grid *grid);
size_t vpds_grid_size(const vpds_grid *grid);

extern "Python" int vpds_py_sizing_batch(const double *x, size_t n, double *r_out, void *user);
"""
)
ffibuilder.set_source(
    "vpds._vpds",
    '#include "vpds.h"\n' + UNITY,
    include_dirs=[str(ROOT / "include"), str(ROOT / "libvpds")],
    # the library's determinism contract: no FMA contraction, no fast-math
    extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off", "-fvisibility=hidden"],
)

if __name__ == "__main__":
    ffibuilder.compile(verbose=True)
