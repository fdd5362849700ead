# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# An output folder holds one run's whole result or says it does not: `morea
# register` owns its folder while it runs, writes its outputs whole or not at
# all (summary.json last), and a rerun clears what earlier runs left behind.
#
# Run as: cmake -DMOREA=<morea executable> -DWORK=<scratch folder> -P OutputFolder.cmake
cmake_minimum_required(VERSION 3.19)

foreach(var MOREA WORK)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "OutputFolder.cmake: pass -D${var}=...")
  endif()
endforeach()
find_program(PYTHON3 NAMES python3 REQUIRED)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

function(run_ok label)
  execute_process(COMMAND "${MOREA}" ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "${label}: exited with '${rc}'\n--- stdout:\n${out}\n--- stderr:\n${err}")
  endif()
  message(STATUS "${label}: ok")
endfunction()

# Names in `folder` (hidden ones included), sorted.
function(list_folder outvar folder)
  file(GLOB names RELATIVE "${folder}" "${folder}/*" "${folder}/.*")
  list(SORT names)
  set(${outvar} "${names}" PARENT_SCOPE)
endfunction()

set(phantom "${WORK}/phantom")
run_ok("phantom" phantom -o "${phantom}" --spacing 4)
set(tiny register --problem "${phantom}" --set ea_population_size=12 --set ea_num_clusters=2
         --set ea_archive_size=30 --set morea_mesh_num_points=80 --set morea_sampling_rate=0.2
         --set preprocess_isotropic_spacing=4 --set seed=2 --set ea_adaptive_steering_activated_at_num_generations=3
         --set ea_num_generations=2)

# --- a rerun clears earlier solution folders and temporary files -------------------------------------
set(reused "${WORK}/reused")
run_ok("first run" ${tiny} --select best-guidance,knee -o "${reused}")
file(MAKE_DIRECTORY "${reused}/weighted_old" "${reused}/.outputs.partial" "${reused}/notes")
file(WRITE "${reused}/weighted_old/fixed_to_moving.h5" "an earlier run's solution")
file(WRITE "${reused}/.outputs.partial/front.csv" "a killed run's staged output")
file(WRITE "${reused}/.front.tmp4242_0.csv" "a killed run's temporary file")
file(WRITE "${reused}/notes/mine.txt" "the user's own file")
run_ok("rerun" ${tiny} --select knee -o "${reused}")
list_folder(names "${reused}")
foreach(gone best_guidance weighted_old .outputs.partial .front.tmp4242_0.csv)
  if(gone IN_LIST names)
    message(FATAL_ERROR "rerun: '${gone}' of an earlier run is still in the folder: ${names}")
  endif()
endforeach()
foreach(kept knee summary.json front.csv notes)
  if(NOT kept IN_LIST names)
    message(FATAL_ERROR "rerun: '${kept}' is missing from the folder: ${names}")
  endif()
endforeach()

# --- a full disk: the run fails, and no output that looks like a result is left ------------------------
# Files are limited to 400 kB (RLIMIT_FSIZE, SIGXFSZ ignored so writes fail with EFBIG): the checkpoint
# fits, the displacement fields do not.
set(full "${WORK}/full")
execute_process(
  COMMAND "${PYTHON3}" -c "import os, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (400000, 400000))
os.execv(sys.argv[1], sys.argv[1:])" "${MOREA}" ${tiny} -o "${full}"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc STREQUAL "0")
  message(FATAL_ERROR "full disk: the run succeeded although no field could be written:\n${out}")
endif()
if(NOT err MATCHES "cannot write")
  message(FATAL_ERROR "full disk: the message does not say what could not be written:\n${err}")
endif()
list_folder(names "${full}")
foreach(name IN LISTS names)
  if(NOT name MATCHES "^(checkpoint\\.bin|\\.morea\\.lock)$")
    message(FATAL_ERROR "full disk: '${name}' was left in the folder (only the checkpoint may stay): ${names}")
  endif()
endforeach()
message(STATUS "full disk: refused cleanly (${names})")

# --- two runs, one folder: the second is refused, naming the first ------------------------------------
# A stand-in first run holds the folder's lock (as `morea register` does, with flock) while the real
# one starts; deterministic, unlike racing two registrations.
set(shared "${WORK}/shared")
file(MAKE_DIRECTORY "${shared}")
execute_process(
  COMMAND "${PYTHON3}" -c "import fcntl, os, subprocess, sys
lock = open(os.path.join(sys.argv[1], '.morea.lock'), 'w')
fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
lock.write('%d\\n' % os.getpid()); lock.flush()
second = subprocess.run(sys.argv[2:], capture_output=True, text=True)
print(os.getpid(), second.returncode, second.stderr.strip())" "${shared}" "${MOREA}" ${tiny} -o "${shared}"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc STREQUAL "0" OR NOT out MATCHES "^([0-9]+) ([0-9]+) (.*)$")
  message(FATAL_ERROR "two runs in one folder: the test's first run failed (${rc}):\n${out}\n${err}")
endif()
set(owner "${CMAKE_MATCH_1}")
set(second_rc "${CMAKE_MATCH_2}")
set(second_err "${CMAKE_MATCH_3}")
if(second_rc STREQUAL "0")
  message(FATAL_ERROR "two runs in one folder: the second run was not refused")
endif()
if(NOT second_err MATCHES "is in use by another run \\(process ${owner}\\)")
  message(FATAL_ERROR "two runs in one folder: the refusal does not name the owner ${owner}:\n${second_err}")
endif()
if(EXISTS "${shared}/front.csv" OR EXISTS "${shared}/parameters.toml")
  message(FATAL_ERROR "two runs in one folder: the refused run wrote into the folder")
endif()
# Once the first run has ended (its lock went with its process), the folder is free.
run_ok("after the owner ended" ${tiny} -o "${shared}")
message(STATUS "two runs in one folder: the second was refused, then ran once the first had ended")
