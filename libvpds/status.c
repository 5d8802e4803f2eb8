/* Names of the status codes and the library's version. */
#include "vpds.h"

const char *vpds_status_string(vpds_status status)
{
    switch (status) {
    case VPDS_OK: return "VPDS_OK: success";
    case VPDS_PAUSED: return "VPDS_PAUSED: stopped by the budget or the progress callback; call again to continue";
    case VPDS_STREAM_END: return "VPDS_STREAM_END: the next event lies at or below t_min";
    case VPDS_ERR_INVALID_ARGUMENT: return "VPDS_ERR_INVALID_ARGUMENT: an argument is out of range";
    case VPDS_ERR_BAD_DESCRIPTOR: return "VPDS_ERR_BAD_DESCRIPTOR: descriptor not from vpds_default_desc() or of an unknown layout";
    case VPDS_ERR_OUT_OF_MEMORY: return "VPDS_ERR_OUT_OF_MEMORY: the allocator failed";
    case VPDS_ERR_UNSUPPORTED: return "VPDS_ERR_UNSUPPORTED: not supported by this version";
    case VPDS_ERR_SIZING: return "VPDS_ERR_SIZING: the sizing function returned an invalid radius";
    case VPDS_ERR_LIPSCHITZ: return "VPDS_ERR_LIPSCHITZ: the sizing function breaks the declared Lipschitz constant";
    case VPDS_ERR_STATE: return "VPDS_ERR_STATE: not valid in the sampler's current state";
    case VPDS_ERR_OVERFLOW: return "VPDS_ERR_OVERFLOW: a size computation would overflow";
    case VPDS_ERR_DOMAIN: return "VPDS_ERR_DOMAIN: the domain function returned NaN, is not "
                                 "1-Lipschitz, or its domain is empty";
    }
    return "unknown vpds_status";
}

#define VPDS_STR2(x) #x
#define VPDS_STR(x) VPDS_STR2(x)
const char *vpds_version_string(void)
{
    return VPDS_STR(VPDS_VERSION_MAJOR) "." VPDS_STR(VPDS_VERSION_MINOR) "." VPDS_STR(VPDS_VERSION_PATCH);
}
