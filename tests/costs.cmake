# Test times in seconds measured on the 2-core CI VM (2026-11-29, a fresh clone, CI=true: slow
# tests reduced): the Werror build's and the sanitizer build's (0: not run there). ctest runs
# the dearest tests first only when it has timings of its own (Testing/Temporary/CTestCostData.txt),
# which a fresh clone has not: it then started them in numbering order, and the longest ones
# (farm.slurm, cli.volume_cli) ran last and alone, with one core idle for a minute per stage.
# These become each test's COST property, ctest's order when it has no timings. Only tests of
# 4 s or more; re-measure when the suite changes much (the table need not be exact to help).
set(GR_TEST_COSTS
  cli.run 58 0
  farm.slurm 51 0
  cli.truth_digest 47 0
  cli.rel_cache 10 16
  integration.tune_default 31 0
  cli.volume_cli 31 58
  unit.ref_coverage 30 0
  unit.ref_adaptive 23 0
  cli.techniques 23 27
  cli.run_sequence 23 38
  cli.report_links 23 39
  cli.capture_own 23 43
  unit.ref_antithetic 21 37
  integration.suite_tune 19 0
  cli.tune_pareto 19 0
  unit.ref_photons 17 0
  integration.ref_cli 17 0
  cli.rel_inputs 16 30
  unit.ref_flux 14 0
  cli.report_viewer 14 26
  cli.pareto_suite 14 0
  integration.eevee_flat 13 0
  integration.caustics 13 0
  cli.rel_outputs 13 25
  cli.compare_fit 13 19
  cli.rel_signals 10 0
  unit.ref_convergence 9 0
  integration.volume_flat 9 21
  cli.report_browser 9 16
  unit.ref_focus 8 0
  cli.usertech_timeout 8 9
  cli.tune_rgb 8 9
  cli.rel_tune_trace 8 17
  cli.export_blender 8 12
  cli.sweep 7 0
  cli.run_progress 7 10
  cli.compare 7 11
  unit.ref_nocap 6 0
  integration.merge 6 16
  cli.rel_readers 6 8
  integration.tune_starts 5 12
  integration.tune_identify 5 10
  cli.watch 5 6
  cli.reference_target 5 25
  integration.usertech_identify 4 6
  integration.ref_hard 4 10
  cli.truth_commands 4 0
  cli.rel_budget 4 8
  cli.export_compare 4 8
  unit.ref_flat 3 7
  cli.suite 3 4
  cli.shafts_render 3 4
  cli.run_verdict 3 7
  cli.run_targets 3 6
  cli.oiio_module 3 6
  cli.exr_half_rgba 3 6
  unit.ref_grid_split 2 5
  unit.ref_disc 2 5
  unit.flip 2 5
  cli.usertech_light 2 4
  cli.rel_numbers 2 4
  cli.preset 2 4
  integration.tune_objective 1 4
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
