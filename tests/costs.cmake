# Test times in seconds measured on the 2-core CI VM (2026-11-29, ninth session: a fresh clone, CI=true: slow
# tests reduced): the Werror build's and the sanitizer build's (0: not run there). ctest runs
# the dearest tests first only when it has timings of its own (Testing/Temporary/CTestCostData.txt),
# which a fresh clone has not: it then started them in numbering order, and the longest ones
# (farm.slurm, cli.volume_cli) ran last and alone, with one core idle for a minute per stage.
# These become each test's COST property, ctest's order when it has no timings. Only tests of
# 4 s or more; re-measure when the suite changes much (the table need not be exact to help).
set(GR_TEST_COSTS
  unit.ref_coverage 60 0
  unit.ref_near 22 0
  farm.slurm 57 0
  integration.tune_default 37 0
  cli.capture_own 32 40
  unit.ref_adaptive 32 0
  cli.run 28 0
  cli.techniques 27 33
  cli.rel_inputs 25 32
  cli.truth_digest 24 0
  integration.suite_tune 24 0
  cli.volume_cli 23 39
  cli.report_links 22 38
  unit.ref_antithetic 19 35
  cli.report_viewer 18 25
  cli.rel_cache 18 18
  cli.pareto_suite 18 0
  cli.tune_pareto 18 0
  cli.compare_fit 17 24
  unit.ref_photons 17 0
  cli.rel_outputs 16 27
  cli.run_sequence 16 9
  cli.export_blender 14 12
  integration.caustics 14 0
  integration.eevee_flat 14 0
  integration.ref_cli 14 0
  unit.ref_flux 14 0
  integration.volume_flat 13 30
  cli.report_browser 12 16
  unit.ref_focus 12 0
  unit.ref_camera_rays 11 0
  cli.rel_signals 11 0
  cli.compare 10 14
  cli.sweep 10 14
  unit.ref_convergence 10 0
  cli.rel_tune_trace 9 15
  cli.usertech_timeout 8 11
  cli.run_progress 8 10
  integration.tune_starts 7 15
  cli.rel_readers 7 9
  integration.merge 10 22
  cli.tune_rgb 6 14
  cli.reference_target 8 20
  integration.ref_hard 6 11
  integration.tune_identify 6 10
  cli.export_compare 5 10
  cli.watch 5 7
  cli.exr_half_rgba 5 6
  unit.ref_nocap 5 0
  cli.rel_budget 4 9
  integration.usertech_identify 4 7
  cli.oiio_module 4 5
  cli.truth_commands 4 0
  integration.shafts_stable 4 0
  cli.run_verdict 3 7
  cli.run_targets 3 6
  cli.shafts_render 3 6
  cli.suite 3 5
  unit.ref_disc 3 5
  cli.usertech_glsl 3 4
  cli.usertech_light 3 4
  unit.flip 2 7
  cli.rel_numbers 2 5
  unit.ref_grid_split 2 5
  cli.preset 2 4
  cli.radial_blur_cli 2 4
  unit.ref_flat 2 4
)
list(LENGTH GR_TEST_COSTS n)
math(EXPR last "${n} - 1")
foreach(i RANGE 0 ${last} 3)
  math(EXPR j "${i} + 1")
  math(EXPR k "${i} + 2")
  list(GET GR_TEST_COSTS ${i} name)
  list(GET GR_TEST_COSTS ${j} cost)
  list(GET GR_TEST_COSTS ${k} cost_sanitize)
  if(GODRAYS_SANITIZE AND cost_sanitize GREATER 0)
    set(cost ${cost_sanitize})
  endif()
  if(TEST ${name})
    set_tests_properties(${name} PROPERTIES COST ${cost})
  endif()
endforeach()
