/* Validation messages: write why an argument is refused into msg (cap bytes, may be NULL) and
 * return the status. For the vpds_*_validate functions, whose callers pass msg and cap. */
#ifndef VPDS_REFUSE_H
#define VPDS_REFUSE_H
#include <stdio.h>

#define VPDSI_REFUSE(st, ...) \
    do { if (msg && cap) snprintf(msg, cap, __VA_ARGS__); return st; } while (0)
#endif
