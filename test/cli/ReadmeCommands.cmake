# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# The `morea` commands of README.md's command-line section, run as written in
# a scratch folder (registrations shortened to 3 generations), and the main
# job of scripts/run-main.sh (`morea demo`), shortened the same way.
#
# Run as: cmake -DMOREA=<morea executable> -DSOURCE=<repo root> -DWORK=<scratch> -P ReadmeCommands.cmake
cmake_minimum_required(VERSION 3.19)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(CREATE_LINK "${SOURCE}/examples" "${WORK}/examples" SYMBOLIC)
file(READ "${SOURCE}/README.md" readme)
string(FIND "${readme}" "## Use from the command line" at)
string(SUBSTRING "${readme}" ${at} -1 section)
string(REGEX MATCH "```bash\n([^`]*)```" block "${section}")
string(REPLACE "\n" ";" lines "${CMAKE_MATCH_1}")
set(commands)
foreach(line IN LISTS lines)
  if(line MATCHES "^morea ")
    string(REGEX REPLACE "  +#.*$" "" line "${line}")
    list(APPEND commands "${line}")
  endif()
endforeach()
list(LENGTH commands count)
if(count LESS 3)
  message(FATAL_ERROR "README.md's command-line section lists ${count} morea commands; expected its bash block")
endif()
list(APPEND commands "morea demo -o demo-out")
foreach(command IN LISTS commands)
  separate_arguments(words UNIX_COMMAND "${command}")
  list(POP_FRONT words)
  list(GET words 0 subcommand)
  if(subcommand STREQUAL "register" OR subcommand STREQUAL "demo")
    list(APPEND words --set ea_num_generations=3 --set ea_adaptive_steering_activated_at_num_generations=2)
  endif()
  execute_process(COMMAND "${MOREA}" ${words} WORKING_DIRECTORY "${WORK}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "README: `${command}` failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "README: `${command}`: ok")
endforeach()
