/* How large a maximal run will be, before it runs: what vpds_estimate reports and what a
 * memory limit is checked against. */
#ifndef VPDS_ESTIMATE_H
#define VPDS_ESTIMATE_H
#include "context.h"
#include "cells.h"
#include "domain.h"

/* The estimate of a maximal run at scale t over pb's box (and the domain when dm->fn is set):
 * r (the store's sizing, r_max known) and the domain are read at a fixed set of points (their
 * call counters advance); fixed_bytes is what the sampler holds whatever it samples.
 * A bad r or domain value is VPDS_ERR_SIZING / VPDS_ERR_DOMAIN, said in the store's sink. */
vpds_status vpdsi_estimate_run(const vpdsi_problem *pb, vpdsi_store *st, vpdsi_domain *dm,
                               double t, size_t fixed_bytes, vpds_run_estimate *out);
#endif
