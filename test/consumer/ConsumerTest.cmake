# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Installs this build into a temporary prefix, builds test/consumer (a
# project of its own) against it with find_package, and runs the example it
# builds on the phantom with the installed `morea`.
#
# Run as: cmake -DBUILD=<this build> -DSOURCE=<repo root> -DWORK=<scratch> -P ConsumerTest.cmake
cmake_minimum_required(VERSION 3.19)
file(REMOVE_RECURSE "${WORK}")
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()
set(prefix "${WORK}/prefix")
run("cmake --install" "${CMAKE_COMMAND}" --install "${BUILD}" --prefix "${prefix}")
foreach(f bin/morea include/MultiObjectiveRegistration/itkMultiObjectiveMeshRegistrationFilter.h
          lib/cmake/MultiObjectiveRegistration/MultiObjectiveRegistrationConfig.cmake)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "cmake --install did not install ${f}")
  endif()
endforeach()
run("configure the consumer" "${CMAKE_COMMAND}" -S "${SOURCE}/test/consumer" -B "${WORK}/build"
    -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
    "-DEXAMPLE_SOURCE=${SOURCE}/examples/RegisterPelvisPhantom.cxx")
run("build the consumer" "${CMAKE_COMMAND}" --build "${WORK}/build")
file(WRITE "${WORK}/parameters.toml" "ea_population_size = 12\nea_num_clusters = 2\nea_archive_size = 30\n"
     "ea_num_generations = 3\nmorea_mesh_num_points = 80\nmorea_sampling_rate = 0.2\n"
     "preprocess_isotropic_spacing = 4.0\nseed = 2\n")
run("installed morea phantom" "${prefix}/bin/morea" phantom --spacing 4 -o "${WORK}/phantom")
run("the consumer's example" "${WORK}/build/RegisterPelvisPhantom" "${WORK}/phantom" "${WORK}/parameters.toml"
    "${WORK}/out" cpu)
if(NOT EXISTS "${WORK}/out/fixed_to_moving.h5")
  message(FATAL_ERROR "the consumer's example wrote no transform:\n${output}")
endif()
message(STATUS "installed, found, built and run:\n${output}")
