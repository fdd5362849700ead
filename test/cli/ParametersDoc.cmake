# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# docs/parameters.md ends with the table `morea parameters` prints: a key
# added, removed or changed without the document following fails here.
# Regenerate the table with `morea parameters` after the document's intro.
#
# Run as: cmake -DMOREA=<morea executable> -DDOC=<docs/parameters.md> -P ParametersDoc.cmake
cmake_minimum_required(VERSION 3.19)
execute_process(COMMAND "${MOREA}" parameters RESULT_VARIABLE rc OUTPUT_VARIABLE table ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "morea parameters failed (${rc}): ${err}")
endif()
file(READ "${DOC}" doc)
string(FIND "${doc}" "| key | default |" start)
if(start LESS 0)
  message(FATAL_ERROR "${DOC} holds no parameter table")
endif()
string(SUBSTRING "${doc}" ${start} -1 documented)
if(NOT documented STREQUAL table)
  message(FATAL_ERROR "${DOC} is out of date: replace its table with the output of `morea parameters`")
endif()
