# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# RegisterPelvisPhantom on the phantom, then `morea register` with the same
# parameters, seed and backend: the two fronts must be the same, and the
# bladder's Dice must improve.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/parameters.toml" "
ea_population_size = 16
ea_num_clusters = 2
ea_archive_size = 40
ea_num_generations = 12
ea_adaptive_steering_activated_at_num_generations = 6
morea_mesh_num_points = 100
morea_sampling_rate = 0.3
preprocess_isotropic_spacing = 4.0
seed = 5
")
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()
run("morea phantom" "${MOREA}" phantom --spacing 3 -o "${WORK}/phantom")
run("RegisterPelvisPhantom" "${EXAMPLE}" "${WORK}/phantom" "${WORK}/parameters.toml" "${WORK}/example" cpu)
message(STATUS "${output}")
foreach(f front.csv fixed_to_moving.h5 moving_to_fixed.h5 warped_moving.nii.gz warped_bladder.nii.gz)
  if(NOT EXISTS "${WORK}/example/${f}")
    message(FATAL_ERROR "RegisterPelvisPhantom did not write ${f}")
  endif()
endforeach()
string(REGEX MATCH "bladder +([0-9.]+) +([0-9.]+)" row "${output}")
if(NOT row OR NOT CMAKE_MATCH_2 GREATER CMAKE_MATCH_1)
  message(FATAL_ERROR "the bladder's Dice did not improve: '${row}'")
endif()
run("morea register" "${MOREA}" register --problem "${WORK}/phantom" --parameters "${WORK}/parameters.toml"
    --backend cpu --select best-guidance -o "${WORK}/cli")
# The same front: the CLI's front.csv has `constraint` and `chosen` columns more.
file(STRINGS "${WORK}/example/front.csv" example_front)
file(STRINGS "${WORK}/cli/front.csv" cli_front)
list(LENGTH example_front n)
list(LENGTH cli_front m)
if(NOT n EQUAL m OR n LESS 3)
  message(FATAL_ERROR "fronts of ${n} and ${m} lines")
endif()
math(EXPR last "${n} - 1")
foreach(i RANGE 1 ${last})
  list(GET example_front ${i} a)
  list(GET cli_front ${i} b)
  string(REGEX REPLACE ",[^,]*,[^,]*$" "" b "${b}")
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "front line ${i} differs: example '${a}', morea register '${b}'")
  endif()
endforeach()
message(STATUS "the example and morea register found the same front of ${last} solutions")
