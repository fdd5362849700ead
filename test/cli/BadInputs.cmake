# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Bad inputs to the `morea` command line: each must exit non-zero, say what is
# wrong on stderr, and leave no output behind that looks valid.
#
# Run as: cmake -DMOREA=<morea executable> -DWORK=<scratch folder> -DSOURCE=<repo root> -P BadInputs.cmake
# The small binary test images are written by python3 (standard library only).
cmake_minimum_required(VERSION 3.19)

foreach(var MOREA WORK)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "BadInputs.cmake: pass -D${var}=...")
  endif()
endforeach()
if(NOT EXISTS "${MOREA}")
  message(FATAL_ERROR "BadInputs.cmake: the morea executable '${MOREA}' does not exist")
endif()
find_program(PYTHON3 NAMES python3)
if(NOT PYTHON3)
  message(FATAL_ERROR "BadInputs.cmake: python3 is needed to write the binary test images")
endif()

file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/in")
set(in "${WORK}/in")

# --- inputs -----------------------------------------------------------------------------------------
# A 20^3 grid of 2 mm voxels: a bright sphere (the structure "blob") on a dark background, shifted by
# 2 mm on the moving image. Then the broken variants.
file(WRITE "${WORK}/make_inputs.py" [=[
import gzip, math, os, struct, sys

out = sys.argv[1]
N, SP = 20, 2.0

def header(dims, etype, spacing, origin=(0.0, 0.0, 0.0), datafile="LOCAL"):
    # ElementDataFile must be the last header line.
    return ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
            "CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\n"
            "Offset = %s\nElementSpacing = %s\nDimSize = %s\nElementType = %s\nElementDataFile = %s\n"
            % (" ".join(map(str, origin)), " ".join(map(str, spacing)), " ".join(map(str, dims)), etype,
               datafile)).encode()

def write(name, data):
    with open(os.path.join(out, name), "wb") as f:
        f.write(data)

def sphere(center_mm, radius_mm):
    on = []
    for k in range(N):
        for j in range(N):
            for i in range(N):
                d = math.dist((i * SP, j * SP, k * SP), center_mm)
                on.append(d <= radius_mm)
    return on

def floats(values):
    return struct.pack("<%df" % len(values), *values)

def uchars(values):
    return bytes(values)

fixed_on = sphere((19.0, 19.0, 19.0), 8.0)
moving_on = sphere((21.0, 19.0, 19.0), 8.0)
fixed = [300.0 if v else -100.0 for v in fixed_on]
moving = [300.0 if v else -100.0 for v in moving_on]
grid = ((N, N, N), (SP, SP, SP))

write("fixed.mha", header(grid[0], "MET_FLOAT", grid[1]) + floats(fixed))
write("moving.mha", header(grid[0], "MET_FLOAT", grid[1]) + floats(moving))
write("blob_fixed.mha", header(grid[0], "MET_UCHAR", grid[1]) + uchars(int(v) for v in fixed_on))
write("blob_moving.mha", header(grid[0], "MET_UCHAR", grid[1]) + uchars(int(v) for v in moving_on))
# An all-zero mask on the image grid.
write("empty.mha", header(grid[0], "MET_UCHAR", grid[1]) + uchars([0] * N ** 3))
# A full mask 5 m away from the images: nothing of it lands on their grid.
write("far.mha", header(grid[0], "MET_UCHAR", grid[1], origin=(5000.0, 5000.0, 5000.0)) + uchars([1] * N ** 3))
# NaN voxels in an otherwise valid image.
nan_image = list(fixed)
nan_image[0] = float("nan")
nan_image[N ** 3 // 2] = float("nan")
write("nan.mha", header(grid[0], "MET_FLOAT", grid[1]) + floats(nan_image))
# 4^3 floats need 256 bytes; give 100.
write("truncated.mha", header((4, 4, 4), "MET_FLOAT", (1.0, 1.0, 1.0)) + bytes(range(100)))
# A NIfTI-1 image whose gzip stream is cut off half-way (an interrupted copy).
def nifti(dims, spacing, data):
    h = bytearray(348)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, dims[0], dims[1], dims[2], 1, 1, 1, 1)
    struct.pack_into("<2h", h, 70, 16, 32)  # datatype FLOAT32, bitpix
    struct.pack_into("<8f", h, 76, 1.0, spacing[0], spacing[1], spacing[2], 1.0, 1.0, 1.0, 1.0)
    struct.pack_into("<2f", h, 108, 352.0, 1.0)  # vox_offset, scl_slope
    h[123] = 2  # millimetres
    struct.pack_into("<2h", h, 252, 0, 1)  # qform_code, sform_code
    struct.pack_into("<12f", h, 280, spacing[0], 0, 0, 0, 0, spacing[1], 0, 0, 0, 0, spacing[2], 0)
    h[344:348] = b"n+1\0"
    return bytes(h) + bytes(4) + data
compressed = gzip.compress(nifti(grid[0], grid[1], floats(moving)))
write("truncated.nii.gz", compressed[: len(compressed) // 2])
# A small cube in the grid's corner, far from the blob (outside a crop to it).
write("corner.mha", header(grid[0], "MET_UCHAR", grid[1]) +
      uchars(int(i < 3 and j < 3 and k < 3) for k in range(N) for j in range(N) for i in range(N)))
# A zero spacing, with a complete data file beside the header.
write("zero_spacing.mhd", header((4, 4, 4), "MET_FLOAT", (0.0, 1.0, 1.0), datafile="zero_spacing.raw"))
write("zero_spacing.raw", floats([1.0] * 64))
]=])
execute_process(
  COMMAND "${PYTHON3}" "${WORK}/make_inputs.py" "${in}"
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "writing the test images with ${PYTHON3} failed (${rc}):\n${out}${err}")
endif()

file(WRITE "${in}/x.nii.gz" "this is a text file, not a NIfTI image\n")
file(WRITE "${in}/fixed_landmarks.txt" "point\n3\n19 19 19\n15 19 19\n23 19 19\n")
file(WRITE "${in}/moving_landmarks.txt" "point\n2\n21 19 19\n17 19 19\n")
file(WRITE "${in}/unknown_key.toml" "preprocess_isotropic_spacing = 2.0\nea_populaton_size = 100\n")
file(WRITE "${in}/out_of_range.toml" "ea_population_size = -3\n")
file(WRITE "${in}/placeholder.toml" "# margin: $margin in a comment is fine\npreprocess_crop_margin = $margin\n")

set(fixed "${in}/fixed.mha")
set(moving "${in}/moving.mha")
set(blob --fixed-structure "blob=${in}/blob_fixed.mha" --moving-structure "blob=${in}/blob_moving.mha")

# --- helpers ----------------------------------------------------------------------------------------
set(checked 0)

# A failed case is recorded and the next case runs; the test fails at the end, listing them all.
macro(case_failed text)
  message(SEND_ERROR "${text}")
  set_property(GLOBAL APPEND PROPERTY MOREA_FAILED_CASES "${label}")
  return()
endmacro()

# expect_failure(<label> OUTPUTS <paths...> FRAGMENTS <regexes...> ARGS <morea args...>)
#   morea must exit non-zero; stderr must match every FRAGMENT (case-insensitive); none of the
#   OUTPUTS (files or folders) may exist afterwards, nor temporary files beside them.
function(expect_failure label)
  cmake_parse_arguments(PARSE_ARGV 1 X "USAGE" "" "OUTPUTS;FRAGMENTS;ARGS")
  execute_process(
    COMMAND "${MOREA}" ${X_ARGS}
    RESULT_VARIABLE rc
    OUTPUT_VARIABLE out
    ERROR_VARIABLE err)
  string(REPLACE ";" " " cmdline "${X_ARGS}")
  set(context "\n  command: morea ${cmdline}\n--- stdout:\n${out}\n--- stderr:\n${err}")
  if(rc STREQUAL "0")
    case_failed("${label}: morea succeeded on a bad input${context}")
  endif()
  if(NOT rc MATCHES "^[0-9]+$")
    case_failed("${label}: morea did not exit normally ('${rc}')${context}")
  endif()
  # Libraries may print warnings first (MetaIO does); the error line must be there.
  if(NOT X_USAGE AND NOT err MATCHES "(^|\n)morea: error: ")
    case_failed("${label}: stderr has no line starting with 'morea: error: '${context}")
  endif()
  string(TOLOWER "${err}" err_lower)
  foreach(fragment IN LISTS X_FRAGMENTS)
    string(TOLOWER "${fragment}" fragment_lower)
    if(NOT err_lower MATCHES "${fragment_lower}")
      case_failed("${label}: the message does not mention '${fragment}'${context}")
    endif()
  endforeach()
  foreach(path IN LISTS X_OUTPUTS)
    if(EXISTS "${path}")
      if(IS_DIRECTORY "${path}")
        file(GLOB_RECURSE contents LIST_DIRECTORIES true "${path}/*")
        case_failed("${label}: output folder '${path}' was created (holding: ${contents})${context}")
      endif()
      case_failed("${label}: output '${path}' was written${context}")
    endif()
    get_filename_component(parent "${path}" DIRECTORY)
    get_filename_component(stem "${path}" NAME_WE)
    file(GLOB temporaries "${parent}/.${stem}.tmp*")
    if(temporaries)
      case_failed("${label}: temporary files were left behind: ${temporaries}${context}")
    endif()
  endforeach()
  string(REGEX MATCH "morea: error: [^\n]*" error_line "${err}")
  if(NOT error_line)
    string(REGEX REPLACE "\n.*" "" error_line "${err}")
  endif()
  message(STATUS "${label}: ok (exit ${rc}: ${error_line})")
endfunction()

# Each case writes (or rather must not write) its own outputs.
function(evaluate_outputs var name)
  set(${var} "${WORK}/${name}.json" "${WORK}/${name}_axial.png" "${WORK}/${name}_coronal.png"
             "${WORK}/${name}_sagittal.png" PARENT_SCOPE)
endfunction()

# --- control: the good inputs work ------------------------------------------------------------------
execute_process(
  COMMAND "${MOREA}" evaluate --fixed "${fixed}" --moving "${moving}" ${blob}
          --fixed-landmarks "${in}/fixed_landmarks.txt" --moving-landmarks "${in}/fixed_landmarks.txt"
          --border-margin 0 -o "${WORK}/control.json"
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
if(NOT rc STREQUAL "0" OR NOT EXISTS "${WORK}/control.json")
  message(FATAL_ERROR "control: evaluate on the good test images failed (${rc}):\n${out}${err}")
endif()
file(READ "${WORK}/control.json" control)
string(JSON control_dice GET "${control}" structures blob dice)
if(NOT control_dice GREATER 0.5 OR NOT control_dice LESS 1)
  message(FATAL_ERROR "control: the blob Dice of a 2 mm shift is ${control_dice}, expected in (0.5, 1)")
endif()
message(STATUS "control: evaluate ok (blob Dice ${control_dice})")
execute_process(
  COMMAND "${MOREA}" preprocess --fixed "${fixed}" --moving "${moving}" ${blob}
          --set preprocess_rigid_structure=none --set preprocess_isotropic_spacing=2 -o "${WORK}/pre-control"
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
if(NOT rc STREQUAL "0" OR NOT EXISTS "${WORK}/pre-control/fixed_masks/blob.nii.gz")
  message(FATAL_ERROR "control: preprocess on the good test images failed (${rc}):\n${out}${err}")
endif()
message(STATUS "control: preprocess ok")

# --- images -----------------------------------------------------------------------------------------
evaluate_outputs(o missing)
expect_failure("missing image" OUTPUTS ${o}
  FRAGMENTS "nosuch\\.nii\\.gz" "does not exist"
  ARGS evaluate --fixed "${in}/nosuch.nii.gz" --moving "${moving}" -o "${WORK}/missing.json" --render "${WORK}/missing")

expect_failure("missing image (preprocess)" OUTPUTS "${WORK}/pre-missing"
  FRAGMENTS "nosuch\\.mha" "does not exist"
  ARGS preprocess --fixed "${fixed}" --moving "${in}/nosuch.mha" ${blob} -o "${WORK}/pre-missing")

expect_failure("missing problem folder" OUTPUTS "${WORK}/pre-nofolder"
  FRAGMENTS "nosuch-folder" "does not exist"
  ARGS preprocess --problem "${in}/nosuch-folder" -o "${WORK}/pre-nofolder")

evaluate_outputs(o text)
expect_failure("text file named .nii.gz" OUTPUTS ${o}
  FRAGMENTS "x\\.nii\\.gz" "cannot read"
  ARGS evaluate --fixed "${in}/x.nii.gz" --moving "${moving}" -o "${WORK}/text.json" --render "${WORK}/text")

evaluate_outputs(o truncated)
expect_failure("truncated .mha" OUTPUTS ${o}
  FRAGMENTS "truncated\\.mha" "is truncated"
  ARGS evaluate --fixed "${fixed}" --moving "${in}/truncated.mha" -o "${WORK}/truncated.json" --render "${WORK}/truncated")

evaluate_outputs(o truncatednii)
expect_failure("truncated .nii.gz" OUTPUTS ${o}
  FRAGMENTS "truncated\\.nii\\.gz"
  ARGS evaluate --fixed "${fixed}" --moving "${in}/truncated.nii.gz" -o "${WORK}/truncatednii.json"
       --render "${WORK}/truncatednii")

evaluate_outputs(o zero)
expect_failure("zero spacing" OUTPUTS ${o}
  FRAGMENTS "zero_spacing\\.mhd" "spacing"
  ARGS evaluate --fixed "${in}/zero_spacing.mhd" --moving "${moving}" -o "${WORK}/zero.json" --render "${WORK}/zero")

expect_failure("NaN voxels" OUTPUTS "${WORK}/pre-nan"
  FRAGMENTS "nan\\.mha" "2 voxels.*nan"
  ARGS preprocess --fixed "${in}/nan.mha" --moving "${moving}" ${blob} -o "${WORK}/pre-nan")

# --- structures -------------------------------------------------------------------------------------
expect_failure("structure on the fixed side only" OUTPUTS "${WORK}/pre-oneside"
  FRAGMENTS "bladder" "moving"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" --fixed-structure "bladder=${in}/blob_fixed.mha"
       --set preprocess_rigid_structure=none -o "${WORK}/pre-oneside")

evaluate_outputs(o empty)
expect_failure("empty mask" OUTPUTS ${o}
  FRAGMENTS "blob" "empty"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" --fixed-structure "blob=${in}/blob_fixed.mha"
       --moving-structure "blob=${in}/empty.mha" -o "${WORK}/empty.json" --render "${WORK}/empty")

evaluate_outputs(o far)
expect_failure("mask off the image" OUTPUTS ${o}
  FRAGMENTS "blob" "far\\.mha" "overlap"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" --fixed-structure "blob=${in}/far.mha"
       --moving-structure "blob=${in}/blob_moving.mha" -o "${WORK}/far.json" --render "${WORK}/far")

evaluate_outputs(o nosource)
expect_failure("missing structure file" OUTPUTS ${o}
  FRAGMENTS "blob" "nosuch_mask\\.mha" "does not exist"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" --fixed-structure "blob=${in}/blob_fixed.mha"
       --moving-structure "blob=${in}/nosuch_mask.mha" -o "${WORK}/nosource.json" --render "${WORK}/nosource")

expect_failure("structure without a name" OUTPUTS "${WORK}/pre-noname"
  FRAGMENTS "--fixed-structure" "NAME=VALUE"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" --fixed-structure "${in}/blob_fixed.mha"
       --moving-structure "blob=${in}/blob_moving.mha" -o "${WORK}/pre-noname")

expect_failure("rigid structure that does not exist" OUTPUTS "${WORK}/pre-rigid"
  FRAGMENTS "nosuch" "blob"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --set preprocess_rigid_structure=nosuch
       -o "${WORK}/pre-rigid")

expect_failure("crop structure that does not exist" OUTPUTS "${WORK}/pre-crop"
  FRAGMENTS "nosuch"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --set preprocess_rigid_structure=none
       --set preprocess_crop_structure=nosuch -o "${WORK}/pre-crop")

# --- landmarks --------------------------------------------------------------------------------------
evaluate_outputs(o landmarks)
expect_failure("landmark count mismatch" OUTPUTS ${o}
  FRAGMENTS "landmark" "3" "2"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" ${blob}
       --fixed-landmarks "${in}/fixed_landmarks.txt" --moving-landmarks "${in}/moving_landmarks.txt"
       -o "${WORK}/landmarks.json" --render "${WORK}/landmarks")

evaluate_outputs(o landmarks1)
expect_failure("landmarks on one side only" OUTPUTS ${o}
  FRAGMENTS "landmark"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" ${blob} --fixed-landmarks "${in}/fixed_landmarks.txt"
       -o "${WORK}/landmarks1.json" --render "${WORK}/landmarks1")

# --- parameters -------------------------------------------------------------------------------------
expect_failure("unknown TOML key" OUTPUTS "${WORK}/pre-key"
  FRAGMENTS "ea_populaton_size" "unknown_key\\.toml"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --parameters "${in}/unknown_key.toml"
       -o "${WORK}/pre-key")

expect_failure("out-of-range TOML value" OUTPUTS "${WORK}/pre-range"
  FRAGMENTS "ea_population_size" "-3"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --parameters "${in}/out_of_range.toml"
       -o "${WORK}/pre-range")

expect_failure("unresolved placeholder" OUTPUTS "${WORK}/pre-placeholder"
  FRAGMENTS "\\$margin" "--var"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --parameters "${in}/placeholder.toml"
       -o "${WORK}/pre-placeholder")

expect_failure("placeholder given another name" OUTPUTS "${WORK}/pre-placeholder2"
  FRAGMENTS "\\$margin"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --parameters "${in}/placeholder.toml"
       --var marg=20 -o "${WORK}/pre-placeholder2")

expect_failure("--set with an unknown key" OUTPUTS "${WORK}/pre-set"
  FRAGMENTS "nosuch_key" "unknown"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --set nosuch_key=1 -o "${WORK}/pre-set")

expect_failure("--set with a value of the wrong type" OUTPUTS "${WORK}/pre-settype"
  FRAGMENTS "preprocess_isotropic_spacing" "abc"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --set preprocess_isotropic_spacing=abc
       -o "${WORK}/pre-settype")

expect_failure("--set out of range" OUTPUTS "${WORK}/pre-setrange"
  FRAGMENTS "preprocess_isotropic_spacing" "must be in"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --set preprocess_isotropic_spacing=0
       -o "${WORK}/pre-setrange")

expect_failure("--set without '='" OUTPUTS "${WORK}/pre-seteq"
  FRAGMENTS "--set" "NAME=VALUE"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --set preprocess_isotropic_spacing
       -o "${WORK}/pre-seteq")

evaluate_outputs(o evalset)
expect_failure("evaluate --set with an unknown key" OUTPUTS ${o}
  FRAGMENTS "nosuch_key"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" ${blob} --set nosuch_key=1
       -o "${WORK}/evalset.json" --render "${WORK}/evalset")

# --- command-line usage (CLI11) ---------------------------------------------------------------------
expect_failure("missing parameter file" USAGE OUTPUTS "${WORK}/pre-noparams"
  FRAGMENTS "nosuch\\.toml"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob} --parameters "${in}/nosuch.toml"
       -o "${WORK}/pre-noparams")

expect_failure("preprocess without -o" USAGE
  FRAGMENTS "output"
  ARGS preprocess --fixed "${fixed}" --moving "${moving}" ${blob})

expect_failure("unknown subcommand" USAGE
  FRAGMENTS "subcommand"
  ARGS frobnicate)

expect_failure("no subcommand" USAGE
  FRAGMENTS "subcommand"
  ARGS)

evaluate_outputs(o badmargin)
expect_failure("non-numeric border margin" USAGE OUTPUTS ${o}
  FRAGMENTS "border-margin"
  ARGS evaluate --fixed "${fixed}" --moving "${moving}" --border-margin wide -o "${WORK}/badmargin.json")
# --- mesh ---------------------------------------------------------------------------------------------
set(o "${WORK}/mesh-out")
expect_failure("mesh: unknown generation method" OUTPUTS ${o} FRAGMENTS "morea_mesh_generation_method" "grid"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set morea_mesh_generation_method=grid -o "${o}")
expect_failure("mesh: malformed structure shares" OUTPUTS ${o} FRAGMENTS "morea_mesh_structure_shares"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set "morea_mesh_structure_shares=blob" -o "${o}")
expect_failure("mesh: negative elasticity factor" OUTPUTS ${o} FRAGMENTS "morea_elasticity_factors" "positive"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set "morea_elasticity_factors=blob=-2" -o "${o}")
expect_failure("mesh: unknown guidance structure" OUTPUTS ${o} FRAGMENTS "liver"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set problem_guidance_selection=liver -o "${o}")
expect_failure("mesh: unknown rigid structure" OUTPUTS ${o} FRAGMENTS "morea_rigid_structures" "femur" "blob"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set morea_rigid_structures=femur -o "${o}")
expect_failure("mesh: negative rigid weight" OUTPUTS ${o} FRAGMENTS "morea_rigid_weight"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set morea_rigid_weight=-1 -o "${o}")
# --objectives-of: a field that is not there, and images not preprocessed; nothing written.
expect_failure("mesh: objectives of a missing field" OUTPUTS ${o} FRAGMENTS "no_such_field.nii.gz"
  ARGS mesh --problem "${WORK}/pre-control" --set morea_mesh_num_points=40
       --objectives-of "x=${in}/no_such_field.nii.gz" -o "${o}")
expect_failure("mesh: objectives on raw images" OUTPUTS ${o} FRAGMENTS "--objectives-of" "preprocessed"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set morea_mesh_num_points=40
       --objectives-of "x=${in}/no_such_field.nii.gz" -o "${o}")
expect_failure("mesh: objectives without a name" OUTPUTS ${o} FRAGMENTS "NAME=FIELD"
  ARGS mesh --problem "${WORK}/pre-control" --objectives-of "${in}/fixed.mha" -o "${o}")
# A problem preprocessed already, preprocessed again: its windowed images would flatten.
set(o "${WORK}/pre-twice")
expect_failure("preprocess: a preprocessed problem again" OUTPUTS ${o} FRAGMENTS "windowing them again" "preprocess_intensity_max = 1"
  ARGS preprocess --problem "${WORK}/pre-control" --set preprocess_rigid_structure=none -o "${o}")
set(o "${WORK}/mesh-out")
expect_failure("phantom: unknown case" OUTPUTS "${WORK}/phantom-knee" FRAGMENTS "knee" "bladder-emptying"
  ARGS phantom --case knee -o "${WORK}/phantom-knee")

# --- register ------------------------------------------------------------------------------------------
set(o "${WORK}/register-out")
expect_failure("register: unknown solution choice" OUTPUTS ${o} FRAGMENTS "bogus" "best-guidance"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --select bogus -o "${o}")
file(WRITE "${WORK}/register-bad-checkpoint/checkpoint.bin" "MOREACKP but not a checkpoint")
expect_failure("register: resume from a damaged checkpoint" OUTPUTS ${o}/front.csv FRAGMENTS "checkpoint"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --set ea_population_size=8 --set ea_num_clusters=2
       --set ea_num_generations=2 --set morea_mesh_num_points=40 --set preprocess_rigid_structure=none --resume -o "${WORK}/register-bad-checkpoint")
file(REMOVE_RECURSE "${WORK}/register-bad-checkpoint")
file(WRITE "${WORK}/benchmark-bad-checkpoint.bin" "MOREACKP but not a checkpoint")
expect_failure("benchmark: start from a damaged checkpoint" OUTPUTS "${WORK}/benchmark-out.json" FRAGMENTS "checkpoint"
  ARGS benchmark --fixed "${fixed}" --moving "${moving}" ${blob} --set ea_population_size=8 --set ea_num_clusters=2
       --set morea_mesh_num_points=40 --set preprocess_rigid_structure=none --backends cpu --probe 0
       --from-checkpoint "${WORK}/benchmark-bad-checkpoint.bin" -o "${WORK}/benchmark-out.json")
# The same structure twice on one image: the second would replace the first.
expect_failure("register: one structure given twice" OUTPUTS ${o}
  FRAGMENTS "structure 'blob' is given twice on the fixed image" "blob_moving\\.mha' both give its mask"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --fixed-structure "blob=${in}/blob_moving.mha"
       --set ea_population_size=8 --set ea_num_clusters=2 --set ea_num_generations=1 --set morea_mesh_num_points=40
       --set preprocess_rigid_structure=none --backend cpu -o "${o}")
# A guidance structure outside the crop: refused before the optimisation, with the reason.
expect_failure("register: a structure that vanishes in preprocessing" OUTPUTS ${o}
  FRAGMENTS "structure 'corner' vanished in preprocessing" "no voxel inside the crop to 'blob'" "preprocess_crop_margin"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --fixed-structure "corner=${in}/corner.mha"
       --moving-structure "corner=${in}/corner.mha" --set preprocess_crop_structure=blob --set preprocess_crop_margin=2
       --set ea_population_size=8 --set ea_num_clusters=2 --set ea_num_generations=1 --set morea_mesh_num_points=40
       --set preprocess_rigid_structure=none --backend cpu -o "${o}")
expect_failure("register: more clusters than solutions" OUTPUTS ${o}
  FRAGMENTS "ea_num_clusters = 9 is more than the population \\(ea_population_size = 8\\)"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --set ea_population_size=8 --set ea_num_clusters=9
       --set ea_num_generations=1 --set morea_mesh_num_points=40 --set preprocess_rigid_structure=none --backend cpu
       -o "${o}")
# A population no machine holds: refused from the parameters, before any work, naming the key.
expect_failure("register: a population too large for the memory" OUTPUTS ${o}
  FRAGMENTS "not enough memory" "a population of 10000000 \\(ea_population_size\\)" "lower ea_population_size"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --set ea_population_size=10000000
       --set ea_num_generations=1 --backend cpu -o "${o}")
# morea benchmark preprocesses as register does, and refuses a vanished structure alike.
expect_failure("benchmark: a structure that vanishes in preprocessing" OUTPUTS "${WORK}/benchmark-vanished.json"
  FRAGMENTS "structure 'corner' vanished in preprocessing"
  ARGS benchmark --fixed "${fixed}" --moving "${moving}" ${blob} --fixed-structure "corner=${in}/corner.mha"
       --moving-structure "corner=${in}/corner.mha" --set preprocess_crop_structure=blob --set preprocess_crop_margin=2
       --set ea_population_size=8 --set ea_num_clusters=2 --set morea_mesh_num_points=40
       --set preprocess_rigid_structure=none --backends cpu --probe 0 -o "${WORK}/benchmark-vanished.json")
file(WRITE "${WORK}/initial-2d.tfm" "#Insight Transform File V1.0\n#Transform 0\nTransform: AffineTransform_double_2_2\n"
  "Parameters: 1 0 0 1 0 0\nFixedParameters: 0 0\n")
expect_failure("register: a 2-D initial transform" OUTPUTS ${o} FRAGMENTS "initial moving transform" "3-D transform"
  ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --set ea_population_size=8 --set ea_num_clusters=2
       --set ea_num_generations=1 --set morea_mesh_num_points=40 --set preprocess_rigid_structure=none
       --initial-transform "${WORK}/initial-2d.tfm" --backend cpu -o "${o}")
# Without a GPU (as on CI), a CUDA backend asked for by name fails before any output is written.
if(NOT EXISTS "/dev/nvidia0")
  expect_failure("register: CUDA without a device" OUTPUTS ${o} FRAGMENTS "backend 'cuda'" "backend auto"
    ARGS register --fixed "${fixed}" --moving "${moving}" ${blob} --set ea_population_size=8 --set ea_num_clusters=2
         --set ea_num_generations=1 --set morea_mesh_num_points=40 --set preprocess_rigid_structure=none
         --backend cuda-texture -o "${o}")
endif()
expect_failure("mesh: too few points" USAGE OUTPUTS ${o} FRAGMENTS "morea_mesh_num_points"
  ARGS mesh --fixed "${fixed}" --moving "${moving}" ${blob} --set morea_mesh_num_points=4 -o "${o}")


get_property(failed GLOBAL PROPERTY MOREA_FAILED_CASES)
if(failed)
  list(LENGTH failed n)
  string(REPLACE ";" "\n  " failed "${failed}")
  message(FATAL_ERROR "cli.bad_inputs: ${n} case(s) failed:\n  ${failed}")
endif()
message(STATUS "cli.bad_inputs: all checks passed")

