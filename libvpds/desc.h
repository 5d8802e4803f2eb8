/* The descriptor's layout cookie (vpds_default_desc writes it, vpds_validate reads it). */
#ifndef VPDS_DESC_H
#define VPDS_DESC_H
#define VPDSI_DESC_COOKIE 0x56504431u /* 'VPD1': layout 1 of vpds_desc */
#endif
