# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# End-to-end test of the `morea` command line on the synthetic phantom:
#   phantom -> preprocess -> evaluate (identity baseline, with renders),
#   evaluate with the phantom's true fields, a TOML parameter file with a
#   $placeholder, and `morea info`.
#
# Run as: cmake -DMOREA=<morea executable> -DWORK=<scratch folder> -DSOURCE=<repo root> -P EndToEnd.cmake
cmake_minimum_required(VERSION 3.19) # string(JSON ...)

foreach(var MOREA WORK)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "EndToEnd.cmake: pass -D${var}=...")
  endif()
endforeach()
if(NOT EXISTS "${MOREA}")
  message(FATAL_ERROR "EndToEnd.cmake: the morea executable '${MOREA}' does not exist")
endif()

file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# morea_ok(<label> ARGS...): runs morea with ARGS, fails the test unless it exits 0;
# leaves its stdout and stderr in MOREA_STDOUT and MOREA_STDERR.
function(morea_ok label)
  string(TIMESTAMP start "%s")
  execute_process(
    COMMAND "${MOREA}" ${ARGN}
    RESULT_VARIABLE rc
    OUTPUT_VARIABLE out
    ERROR_VARIABLE err)
  string(TIMESTAMP stop "%s")
  math(EXPR seconds "${stop} - ${start}")
  if(NOT rc STREQUAL "0")
    string(REPLACE ";" " " cmdline "${ARGN}")
    message(FATAL_ERROR "${label}: `morea ${cmdline}` exited with '${rc}'\n--- stdout:\n${out}\n--- stderr:\n${err}")
  endif()
  message(STATUS "${label}: ok (${seconds} s)")
  set(MOREA_STDOUT "${out}" PARENT_SCOPE)
  set(MOREA_STDERR "${err}" PARENT_SCOPE)
endfunction()

function(expect_files label)
  foreach(f IN LISTS ARGN)
    if(NOT EXISTS "${f}")
      message(FATAL_ERROR "${label}: expected output '${f}' is missing")
    endif()
    if(NOT IS_DIRECTORY "${f}")
      file(SIZE "${f}" size)
      if(size EQUAL 0)
        message(FATAL_ERROR "${label}: output '${f}' is empty")
      endif()
    endif()
  endforeach()
endfunction()

# json_number(<out var> <label> <json text> <member path...>): a numeric member, or a test failure.
function(json_number outvar label json)
  string(JSON value ERROR_VARIABLE jerr GET "${json}" ${ARGN})
  if(jerr)
    string(REPLACE ";" "." where "${ARGN}")
    message(FATAL_ERROR "${label}: no '${where}' in the JSON: ${jerr}\n${json}")
  endif()
  if(NOT value MATCHES "^-?[0-9]+(\\.[0-9]*)?([eE][-+]?[0-9]+)?$")
    string(REPLACE ";" "." where "${ARGN}")
    message(FATAL_ERROR "${label}: '${where}' is '${value}', not a number")
  endif()
  set(${outvar} "${value}" PARENT_SCOPE)
endfunction()

# --- info -------------------------------------------------------------------------------------------
morea_ok("info" info)
if(NOT MOREA_STDOUT MATCHES "morea [0-9]")
  message(FATAL_ERROR "info: stdout does not name the version:\n${MOREA_STDOUT}")
endif()

# --- phantom ----------------------------------------------------------------------------------------
set(phantom "${WORK}/phantom")
morea_ok("phantom" phantom -o "${phantom}" --spacing 4)
expect_files("phantom"
  "${phantom}/fixed.nii.gz"
  "${phantom}/moving.nii.gz"
  "${phantom}/fixed_masks/bladder.nii.gz"
  "${phantom}/moving_masks/bladder.nii.gz"
  "${phantom}/fixed_landmarks.txt"
  "${phantom}/moving_landmarks.txt"
  "${phantom}/true_fixed_to_moving.nii.gz"
  "${phantom}/true_moving_to_fixed.nii.gz"
  "${phantom}/phantom.json")
file(READ "${phantom}/phantom.json" phantom_json)
json_number(phantom_spacing "phantom.json" "${phantom_json}" spacing_mm)
if(NOT phantom_spacing EQUAL 4)
  message(FATAL_ERROR "phantom.json: spacing_mm is ${phantom_spacing}, expected 4")
endif()
file(GLOB leftovers "${phantom}/.*" "${phantom}/*/.*")
if(leftovers)
  message(FATAL_ERROR "phantom: temporary files were left behind: ${leftovers}")
endif()
# A case of the suite: its name and one kind per landmark in phantom.json.
set(emptying "${WORK}/phantom-emptying")
morea_ok("phantom --case" phantom --case bladder-emptying -o "${emptying}" --spacing 6)
file(READ "${emptying}/phantom.json" emptying_json)
string(JSON emptying_case GET "${emptying_json}" case)
string(JSON emptying_kinds LENGTH "${emptying_json}" landmark_kinds)
file(STRINGS "${emptying}/fixed_landmarks.txt" emptying_lines)
list(GET emptying_lines 1 emptying_count)
if(NOT emptying_case STREQUAL "bladder-emptying" OR NOT emptying_kinds EQUAL emptying_count OR emptying_count LESS 40)
  message(FATAL_ERROR "phantom --case: case '${emptying_case}', ${emptying_kinds} landmark kinds for ${emptying_count} landmarks")
endif()

# --- preprocess -------------------------------------------------------------------------------------
set(pre "${WORK}/pre")
morea_ok("preprocess" preprocess --problem "${phantom}" --set preprocess_isotropic_spacing=3 -o "${pre}")
set(preprocess_stdout "${MOREA_STDOUT}")
if(NOT preprocess_stdout MATCHES "bladder")
  message(FATAL_ERROR "preprocess: stdout does not mention 'bladder':\n${preprocess_stdout}")
endif()
expect_files("preprocess"
  "${pre}/fixed.nii.gz"
  "${pre}/moving.nii.gz"
  "${pre}/fixed_masks"
  "${pre}/fixed_masks/bladder.nii.gz"
  "${pre}/moving_masks/bladder.nii.gz"
  "${pre}/fixed_points/bladder.csv"
  "${pre}/moving_points/bladder.csv"
  "${pre}/preprocess.json"
  "${pre}/rigid_fixed_to_moving.tfm")
file(READ "${pre}/preprocess.json" pre_json)
json_number(pre_spacing "preprocess.json" "${pre_json}" spacing_mm)
if(NOT pre_spacing EQUAL 3)
  message(FATAL_ERROR "preprocess.json: spacing_mm is ${pre_spacing}, expected 3 (from --set)")
endif()
string(JSON pre_crop GET "${pre_json}" crop_structure)
if(NOT pre_crop STREQUAL "bladder")
  message(FATAL_ERROR "preprocess.json: crop_structure is '${pre_crop}', expected 'bladder' (the deforming organ)")
endif()
set(pre_size)
foreach(i 0 1 2)
  json_number(n "preprocess.json" "${pre_json}" size ${i})
  list(APPEND pre_size ${n})
endforeach()
file(GLOB leftovers "${pre}/.*" "${pre}/*/.*")
if(leftovers)
  message(FATAL_ERROR "preprocess: temporary files were left behind: ${leftovers}")
endif()

# --- mesh model of the preprocessed problem ---------------------------------------------------------
set(meshdir "${WORK}/mesh")
morea_ok("mesh" mesh --problem "${pre}" --set morea_mesh_num_points=200 --samples 1 -o "${meshdir}")
expect_files("mesh"
  "${meshdir}/mesh.json"
  "${meshdir}/mesh_moving.vtu"
  "${meshdir}/mesh_fixed.vtu"
  "${meshdir}/initial_1_mesh_moving.vtu"
  "${meshdir}/initial_1_fixed_to_moving.nii.gz"
  "${meshdir}/initial_1_moving_to_fixed.nii.gz")
file(READ "${meshdir}/mesh.json" mesh_json)
json_number(mesh_points "mesh.json" "${mesh_json}" points)
json_number(mesh_steiner "mesh.json" "${mesh_json}" points_by_origin steiner)
json_number(mesh_surface "mesh.json" "${mesh_json}" points_by_origin surface)
json_number(mesh_groups "mesh.json" "${mesh_json}" parallel_groups)
math(EXPR mesh_expected "200 + ${mesh_steiner}")
if(NOT mesh_points EQUAL mesh_expected OR mesh_surface LESS 10 OR mesh_groups LESS 2)
  message(FATAL_ERROR "mesh.json: ${mesh_points} points (${mesh_surface} on the bladder surface), "
                      "${mesh_groups} parallel groups:\n${mesh_json}")
endif()
# The objectives of known maps on this mesh: the truth matches the contours far
# better than the identity; the truth's inverse, taken the wrong way round, worse.
morea_ok("mesh objectives" mesh --problem "${pre}" --set morea_mesh_num_points=200 -o "${WORK}/mesh-objectives"
  --objectives-of "truth=${phantom}/true_moving_to_fixed.nii.gz" "reversed=${phantom}/true_fixed_to_moving.nii.gz")
file(READ "${WORK}/mesh-objectives/mesh.json" objectives_json)
json_number(identity_magnitude "mesh.json" "${objectives_json}" objectives identity magnitude)
json_number(identity_guidance "mesh.json" "${objectives_json}" objectives identity guidance)
json_number(truth_magnitude "mesh.json" "${objectives_json}" objectives truth magnitude)
json_number(truth_guidance "mesh.json" "${objectives_json}" objectives truth guidance)
json_number(reversed_guidance "mesh.json" "${objectives_json}" objectives reversed guidance)
if(NOT identity_magnitude EQUAL 0 OR NOT truth_magnitude GREATER 0)
  message(FATAL_ERROR "mesh objectives: magnitude identity ${identity_magnitude}, truth ${truth_magnitude}:\n"
                      "${objectives_json}")
endif()
if(NOT truth_guidance LESS identity_guidance OR NOT identity_guidance LESS reversed_guidance)
  message(FATAL_ERROR "mesh objectives: guidance truth ${truth_guidance}, identity ${identity_guidance}, "
                      "reversed ${reversed_guidance} (expected in this order)")
endif()
if(NOT MOREA_STDOUT MATCHES "objectives of truth: magnitude")
  message(FATAL_ERROR "mesh objectives: nothing printed:\n${MOREA_STDOUT}")
endif()

file(READ "${meshdir}/mesh_fixed.vtu" vtu LIMIT 400)
if(NOT vtu MATCHES "UnstructuredGrid")
  message(FATAL_ERROR "mesh_fixed.vtu is not a VTK unstructured grid:\n${vtu}")
endif()

# --- evaluate the identity baseline on the preprocessed problem -------------------------------------
morea_ok("evaluate baseline" evaluate --problem "${pre}" -o "${WORK}/scores.json" --render "${WORK}/render")
expect_files("evaluate baseline"
  "${WORK}/scores.json"
  "${WORK}/render_axial.png"
  "${WORK}/render_coronal.png"
  "${WORK}/render_sagittal.png")
if(NOT MOREA_STDOUT MATCHES "bladder")
  message(FATAL_ERROR "evaluate baseline: the printed table does not list 'bladder':\n${MOREA_STDOUT}")
endif()
file(READ "${WORK}/scores.json" scores)
if(NOT scores MATCHES "\"dice\"")
  message(FATAL_ERROR "scores.json has no \"dice\":\n${scores}")
endif()
json_number(baseline_dice "scores.json" "${scores}" structures bladder dice)
if(NOT baseline_dice LESS 0.6 OR baseline_dice LESS 0)
  message(FATAL_ERROR "scores.json: the baseline bladder Dice is ${baseline_dice}; the bladder fills a lot "
                      "between the phantom's images, so the identity should score < 0.6")
endif()
message(STATUS "baseline bladder Dice ${baseline_dice}")
file(READ "${WORK}/render_axial.png" png_magic LIMIT 8 HEX)
if(NOT png_magic STREQUAL "89504e470d0a1a0a")
  message(FATAL_ERROR "render_axial.png is not a PNG (starts with ${png_magic})")
endif()

# --- evaluate the true deformation on the original phantom ------------------------------------------
morea_ok("evaluate truth" evaluate --problem "${phantom}"
  --field "${phantom}/true_fixed_to_moving.nii.gz"
  --inverse-field "${phantom}/true_moving_to_fixed.nii.gz"
  --border-margin 0 -o "${WORK}/truth.json")
file(READ "${WORK}/truth.json" truth)
json_number(truth_dice "truth.json" "${truth}" structures bladder dice)
json_number(truth_tre "truth.json" "${truth}" landmarks tre_mean_mm)
json_number(truth_count "truth.json" "${truth}" landmarks count)
json_number(truth_ic "truth.json" "${truth}" inverse_consistency mean_mm)
json_number(truth_margin "truth.json" "${truth}" border_margin_mm)
message(STATUS "true field: bladder Dice ${truth_dice}, TRE mean ${truth_tre} mm over ${truth_count} landmarks, "
               "inverse consistency mean ${truth_ic} mm")
if(NOT truth_dice GREATER 0.9 OR truth_dice GREATER 1)
  message(FATAL_ERROR "truth.json: the true field's bladder Dice is ${truth_dice}, expected > 0.9")
endif()
if(NOT truth_count GREATER 0)
  message(FATAL_ERROR "truth.json: no landmarks were scored")
endif()
if(NOT truth_tre LESS 0.5)
  message(FATAL_ERROR "truth.json: the true field's landmark TRE mean is ${truth_tre} mm, expected < 0.5 mm")
endif()
if(NOT truth_ic LESS 0.5)
  message(FATAL_ERROR "truth.json: the true fields' inverse consistency mean is ${truth_ic} mm, expected < 0.5 mm")
endif()
if(NOT truth_margin EQUAL 0)
  message(FATAL_ERROR "truth.json: border_margin_mm is ${truth_margin}, expected 0 (from --border-margin)")
endif()

# --- a TOML parameter file with a $placeholder filled by --var --------------------------------------
# The margin shrinks from the default 30 mm to 20 mm, so the crop must not grow and must shrink somewhere.
# Placeholders are substituted in values and strings, but not in comments.
file(WRITE "${WORK}/params.toml" [=[
# Preprocessing for the CLI test; costs $nothing (a comment is not substituted).
problem_id = "phantom, crop margin $margin mm"
preprocess_isotropic_spacing = 3.0
preprocess_crop_margin = $margin
]=])
set(pre_toml "${WORK}/pre-toml")
morea_ok("preprocess with --parameters/--var" preprocess --problem "${phantom}"
  --parameters "${WORK}/params.toml" --var margin=20 -o "${pre_toml}")
expect_files("preprocess with --parameters/--var" "${pre_toml}/fixed.nii.gz" "${pre_toml}/preprocess.json")
file(READ "${pre_toml}/preprocess.json" toml_json)
json_number(toml_spacing "preprocess.json (TOML)" "${toml_json}" spacing_mm)
if(NOT toml_spacing EQUAL 3)
  message(FATAL_ERROR "preprocess.json (TOML): spacing_mm is ${toml_spacing}, expected 3 from the parameter file")
endif()
set(shrunk FALSE)
foreach(i 0 1 2)
  json_number(n "preprocess.json (TOML)" "${toml_json}" size ${i})
  list(GET pre_size ${i} n30)
  if(n GREATER n30)
    message(FATAL_ERROR "preprocess with margin 20: size[${i}] is ${n}, larger than ${n30} with the default margin 30")
  endif()
  if(n LESS n30)
    set(shrunk TRUE)
  endif()
endforeach()
if(NOT shrunk)
  message(FATAL_ERROR "preprocess with --var margin=20: the crop (${toml_json}) is no smaller than with the "
                      "default 30 mm margin (${pre_size}); was the placeholder substituted?")
endif()

# --- register: a tiny MOREA run on the phantom, then a killed run resumed ------------------------------
set(tiny --set ea_population_size=12 --set ea_num_clusters=2 --set ea_archive_size=30 --set morea_mesh_num_points=80
         --set morea_sampling_rate=0.2 --set preprocess_isotropic_spacing=4 --set seed=2
         --set ea_adaptive_steering_activated_at_num_generations=3)
set(reg "${WORK}/register")
morea_ok("register" register --problem "${phantom}" ${tiny} --set ea_num_generations=6 --checkpoint-every 2
  -o "${reg}")
expect_files("register"
  "${reg}/front.csv" "${reg}/front.json" "${reg}/generations.csv" "${reg}/summary.json" "${reg}/checkpoint.bin"
  "${reg}/parameters.toml" "${reg}/rigid_fixed_to_moving.tfm"
  "${reg}/best_guidance/preprocessed_fixed_to_moving.nii.gz" "${reg}/best_guidance/preprocessed_moving_to_fixed.nii.gz"
  "${reg}/best_guidance/fixed_to_moving.h5" "${reg}/best_guidance/moving_to_fixed.h5"
  "${reg}/best_guidance/mesh_moving.vtu" "${reg}/best_guidance/mesh_fixed.vtu" "${reg}/best_guidance/scores.json"
  "${reg}/knee/fixed_to_moving.h5")
# --- register --initial-transform: an affine file replaces the rigid step ----------------------------------
file(WRITE "${WORK}/initial.tfm" "#Insight Transform File V1.0\n#Transform 0\nTransform: AffineTransform_double_3_3\n"
  "Parameters: 1 0 0 0 1 0 0 0 1 4 -7 12\nFixedParameters: 0 0 0\n")
execute_process(COMMAND "${MOREA}" register --problem "${phantom}" ${tiny} --set ea_num_generations=2
  --initial-transform "${WORK}/initial.tfm" --select best-guidance -o "${WORK}/initial"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "pre-aligned by the AffineTransform given")
  message(FATAL_ERROR "register --initial-transform (${rc}):\n${out}\n${err}")
endif()
file(READ "${WORK}/initial/rigid_fixed_to_moving.tfm" written)
if(NOT written MATCHES "AffineTransform_double_3_3" OR NOT written MATCHES "Parameters: 1 0 0 0 1 0 0 0 1 4 -7 12")
  message(FATAL_ERROR "register --initial-transform: the pre-alignment written is not the one given:\n${written}")
endif()

# --- register num_runs = 2, zip = true: two seeds in two folders, one archive ---------------------------
set(runs "${WORK}/runs")
file(REMOVE_RECURSE "${runs}" "${runs}.zip")
morea_ok("register num_runs zip" register --problem "${phantom}" ${tiny} --set ea_num_generations=2 --set num_runs=2
  --set zip=true --select best-guidance -o "${runs}")
expect_files("register num_runs zip" "${runs}/parameters.toml" "${runs}/run_1/summary.json"
  "${runs}/run_2/summary.json" "${runs}/run_2/best_guidance/fixed_to_moving.h5" "${runs}.zip")
file(READ "${runs}/run_2/summary.json" run2)
string(JSON run2_seed GET "${run2}" seed)
if(NOT run2_seed EQUAL 3)
  message(FATAL_ERROR "register num_runs: the second run's seed is ${run2_seed}, not the first's (2) plus 1")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E tar tf "${runs}.zip" OUTPUT_VARIABLE listed RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT listed MATCHES "runs/run_2/best_guidance/fixed_to_moving.h5")
  message(FATAL_ERROR "register zip: the archive does not list the second run's transform (${rc}):\n${listed}")
endif()
file(MAKE_DIRECTORY "${WORK}/unzipped")
execute_process(COMMAND ${CMAKE_COMMAND} -E tar xf "${runs}.zip" WORKING_DIRECTORY "${WORK}/unzipped" RESULT_VARIABLE rc)
file(READ "${WORK}/unzipped/runs/run_2/summary.json" unzipped)
if(NOT rc EQUAL 0 OR NOT unzipped STREQUAL run2)
  message(FATAL_ERROR "register zip: the unpacked summary differs from the written one (${rc})")
endif()

file(STRINGS "${reg}/generations.csv" gen_lines)
list(LENGTH gen_lines gen_count)
if(NOT gen_count EQUAL 8) # header, generation 0 (initial population), 1..6
  message(FATAL_ERROR "register: generations.csv has ${gen_count} lines, expected 8")
endif()
file(READ "${reg}/summary.json" reg_json)
json_number(reg_dice "summary.json" "${reg_json}" solutions best_guidance scores structures bladder dice)
json_number(reg_fold "summary.json" "${reg_json}" solutions best_guidance scores jacobian_nonpositive_fraction)
if(reg_fold GREATER 0)
  message(FATAL_ERROR "register: the best-guidance solution folds (Jacobian <= 0 in ${reg_fold} of the voxels)")
endif()
# Stage times: the command's whole time covers its stages; the fields written
# beside the rest of the outputs are whole gzip files.
json_number(reg_command "summary.json" "${reg_json}" seconds command)
json_number(reg_outputs "summary.json" "${reg_json}" seconds outputs)
json_number(reg_optimisation "summary.json" "${reg_json}" seconds optimisation)
json_number(reg_load "summary.json" "${reg_json}" seconds load)
json_number(reg_files "summary.json" "${reg_json}" seconds outputs_parts files)
if(reg_command LESS reg_optimisation OR reg_command LESS reg_outputs OR reg_outputs LESS reg_files OR NOT reg_load GREATER 0)
  message(FATAL_ERROR "register: stage times do not add up: command ${reg_command} s, optimisation "
          "${reg_optimisation} s, outputs ${reg_outputs} s (files ${reg_files} s), load ${reg_load} s")
endif()
if(NOT MOREA_STDOUT MATCHES "times: load [0-9.e-]+ s, preprocessing")
  message(FATAL_ERROR "register: stdout lacks the stage times:\n${MOREA_STDOUT}")
endif()
foreach(f preprocessed_fixed_to_moving preprocessed_moving_to_fixed)
  file(READ "${reg}/knee/${f}.nii.gz" head LIMIT 2 HEX)
  if(NOT head STREQUAL "1f8b")
    message(FATAL_ERROR "register: knee/${f}.nii.gz is not a gzip file (starts with ${head})")
  endif()
endforeach()

file(READ "${reg}/generations.csv" gen_csv)
if(NOT gen_csv MATCHES "seconds_device_kernels,seconds_device_span,samples")
  message(FATAL_ERROR "register: generations.csv lacks the device span column")
endif()

# --- register --refusal-bound off: every candidate sampled, the same front ------------------------------
set(reg_all "${WORK}/register-sample-all")
morea_ok("register --refusal-bound off" register --problem "${phantom}" ${tiny} --set ea_num_generations=6
  --refusal-bound off -o "${reg_all}")
file(READ "${reg}/front.csv" front_bounded)
file(READ "${reg_all}/front.csv" front_all)
if(NOT front_bounded STREQUAL front_all)
  message(FATAL_ERROR "register: the front with --refusal-bound off differs from the default run's")
endif()
file(STRINGS "${reg}/generations.csv" bounded_lines)
list(REMOVE_AT bounded_lines 0)
set(bounded_skipped 0)
foreach(line IN LISTS bounded_lines)
  string(REPLACE "," ";" fields "${line}")
  list(GET fields 23 skipped) # bound_skipped
  math(EXPR bounded_skipped "${bounded_skipped} + ${skipped}")
endforeach()
if(NOT bounded_skipped GREATER 0)
  message(FATAL_ERROR "register: the refusal bound skipped no candidate in 6 generations")
endif()

# --- benchmark: late generations from the register run's checkpoint -----------------------------------
set(bench_json "${WORK}/benchmark-late.json")
morea_ok("benchmark --from-checkpoint" benchmark --problem "${phantom}" ${tiny} --set ea_num_generations=8
  --backends cpu --cpu-generations 2 --probe 0 --from-checkpoint "${reg}/checkpoint.bin" -o "${bench_json}")
file(READ "${bench_json}" late_json)
json_number(late_first "benchmark JSON" "${late_json}" runs cpu first_generation)
json_number(late_count "benchmark JSON" "${late_json}" runs cpu generations)
json_number(late_generation "benchmark JSON" "${late_json}" runs cpu per_generation 0 generation)
if(NOT late_first EQUAL 6 OR NOT late_count EQUAL 2 OR NOT late_generation EQUAL 7)
  message(FATAL_ERROR "benchmark --from-checkpoint: started at generation ${late_first} and ran ${late_count} "
                      "(first ${late_generation}); expected 6, 2 and 7")
endif()

# Killed and resumed: the same seed ends with the same front as one uninterrupted run.
set(full "${WORK}/register-full")
morea_ok("register (uninterrupted)" register --problem "${phantom}" ${tiny} --set ea_num_generations=30
  --checkpoint-every 0 --select best-guidance -o "${full}")
set(killed "${WORK}/register-killed")
execute_process(COMMAND "${MOREA}" register --problem "${phantom}" ${tiny} --set ea_num_generations=30
  --checkpoint-every 4 --select best-guidance --kill-after-generation 13 -o "${killed}" RESULT_VARIABLE rc
  OUTPUT_QUIET ERROR_QUIET)
if(rc STREQUAL "0" OR EXISTS "${killed}/front.csv" OR NOT EXISTS "${killed}/checkpoint.bin")
  message(FATAL_ERROR "register --kill-after-generation: the run was not killed after its checkpoint (exit '${rc}')")
endif()
morea_ok("register --resume" register --problem "${phantom}" ${tiny} --set ea_num_generations=30
  --checkpoint-every 4 --select best-guidance --resume -o "${killed}")
if(NOT MOREA_STDOUT MATCHES "resumed from generation 12")
  message(FATAL_ERROR "register --resume: did not resume:\n${MOREA_STDOUT}")
endif()
file(READ "${full}/front.csv" front_full)
file(READ "${killed}/front.csv" front_resumed)
if(NOT front_full STREQUAL front_resumed)
  message(FATAL_ERROR "register --resume: the front differs from the uninterrupted run's\n--- uninterrupted:\n"
                      "${front_full}\n--- resumed:\n${front_resumed}")
endif()
message(STATUS "register: killed after generation 13, resumed from the checkpoint of 12; same front")

message(STATUS "cli.end_to_end: all checks passed")
