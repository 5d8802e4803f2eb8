/* What the library itself reads of a built-in mask (vpds_mask, mask.c). */
#ifndef VPDS_MASK_H
#define VPDS_MASK_H
#include "vpds.h"

/* The mask's dimension (its cells' axes), or 0 when user is not a live vpds_mask: a sampler
 * whose desc.domain is vpds_mask_sdf checks it against its own (a mask of another dimension
 * would be read at coordinates the sampler never writes). */
int vpdsi_mask_dim(const void *user);

#endif
