#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# AddressSanitizer and UndefinedBehaviorSanitizer (GCC) over the plain C++
# layers: the core's and the mesh layer's unit tests, then a small
# registration through `morea` (phantom, preprocessing, mesh, MO-RV-GOMEA on
# the CPU, outputs), which takes the ITK layer along. Built without CUDA (the
# device's code is checked with compute-sanitizer on a GPU machine) in its own
# folder, build-asan (or $1), kept between runs so that a rerun compiles only
# what changed. Any report fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build-asan}"
jobs="$(nproc)"
# UBSan's reports stay recoverable so that its suppressions (a fault in ITK's
# headers) apply; halt_on_error below makes every other one fatal.
flags="-fsanitize=address,undefined -fno-omit-frame-pointer"
# -O1 -g: readable reports at a third of -O0's test time; asserts stay on.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" -DMOREA_ENABLE_CUDA=OFF >/dev/null
cmake --build "$build" -j"$jobs" --target MOREACoreTests MOREAMeshTests morea

# Leaks are reported by the sanitizer's leak check (LeakSanitizer) at exit.
# The mesh layer runs TetGen in child processes and reports a crash there by
# its signal (MeshRobustnessTest crashes one on purpose): ASan's own SEGV
# handler would turn it into exit status 1, so the signals are left alone.
export ASAN_OPTIONS="detect_leaks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:halt_on_error=1:handle_segv=0:handle_sigbus=0:handle_sigfpe=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$PWD/scripts/sanitizer-undefined.supp"
# LeakSanitizer's suppressions: a one-byte singleton ITK allocates at exit (the file says why).
export LSAN_OPTIONS="suppressions=$PWD/scripts/sanitizer-leak.supp:print_suppressions=0"
"$build/test/MOREACoreTests" --gtest_brief=1
"$build/test/MOREAMeshTests" --gtest_brief=1

# A small registration end to end: every stage of `morea register`, then a resume from its checkpoint.
work="$PWD/$build/sanitizer-registration"
rm -rf "$work"
"$build/bin/morea" phantom -o "$work/phantom" >/dev/null
"$build/bin/morea" register --problem "$work/phantom" -o "$work/register" --backend cpu \
  --set ea_population_size=12 --set ea_num_clusters=2 --set ea_archive_size=30 --set morea_mesh_num_points=80 \
  --set morea_sampling_rate=0.2 --set preprocess_isotropic_spacing=4 --set ea_num_generations=4 \
  --set ea_adaptive_steering_activated_at_num_generations=2 --checkpoint-every 2 >/dev/null
"$build/bin/morea" register --problem "$work/phantom" -o "$work/register" --backend cpu --resume \
  --set ea_population_size=12 --set ea_num_clusters=2 --set ea_archive_size=30 --set morea_mesh_num_points=80 \
  --set morea_sampling_rate=0.2 --set preprocess_isotropic_spacing=4 --set ea_num_generations=6 \
  --set ea_adaptive_steering_activated_at_num_generations=2 --checkpoint-every 2 >/dev/null
echo "sanitizers: no reports"
