/* Benchmark of the ground truth (a program, not a timed test): the hot loop's lookups per
 * second with 1 and 2 threads, next to Embree's raw occlusion-ray throughput on the same
 * scene, measured in the same run. Figures: docs/benchmarks.md. */
#ifndef GR_REF_BENCH_H
#define GR_REF_BENCH_H

#include "common/status.h"
#include "scene/scene.h"

typedef struct gr_ref_bench_result {
    double occluded_occluders_per_s;  /* rtcOccluded1, random rays vs the occluders, 1 thread */
    double occluded_surface_per_s;    /* rtcOccluded1, random rays vs the surface mesh, 1 thread */
    double point_queries_per_s;       /* beam lookups alone (the grid cell, box and containment tests), 1 thread */
    double qps[2];                    /* hot-loop lookups per second, 1 and 2 threads */
    double wall_s[2];                 /* render wall time, 1 and 2 threads */
    double speedup;                   /* wall_s[0] / wall_s[1] */
    int identical;                    /* 1 if both renders gave the same bytes */
    double frac_se_1pct;              /* of the 2-thread render */
    long long surface_triangles, beam_prims;
} gr_ref_bench_result;

gr_status gr_ref_bench(const gr_scene *s, gr_ref_bench_result *out, gr_error *err);

#endif
