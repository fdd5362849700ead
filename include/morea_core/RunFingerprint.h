// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: what a run's front depends on, as a list of
// key = value entries (inputs, preprocessing and objective parameters, the
// mesh). A checkpoint stores it, and a resume whose fingerprint differs is
// refused, naming the first key that differs: continuing an optimisation on
// other data or objectives would give a front that belongs to neither run.
#ifndef morea_RunFingerprint_h
#define morea_RunFingerprint_h

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace morea_core
{
class ParameterSet;

class RunFingerprint
{
public:
  using Entry = std::pair<std::string, std::string>;

  /** Adds (or replaces) `key`. Order is kept: the first difference found is
   *  the first differing key in this order. */
  void
  Add(const std::string & key, const std::string & value);
  /** `key` = the hash of `size` bytes ("xxh64:" and 16 hexadecimal digits):
   *  for voxels, points and meshes, too large to store. */
  void
  AddHash(const std::string & key, const void * data, std::size_t size);

  /** Every parameter that can change the front (ParameterChangesTheFront). */
  void
  AddParameters(const ParameterSet & parameters);

  /** How the backend named `backendName` (EvaluationBackend::Name) samples
   *  the images, under "evaluation backend": the cpu and cuda-exact backends
   *  agree to rounding, the texture path (cuda-texture) only within about
   *  1e-4 per objective, so a front continued on the other would mix both. */
  void
  AddEvaluationBackend(const std::string & backendName);

  const std::vector<Entry> &
  Entries() const
  {
    return m_Entries;
  }
  bool
  Empty() const
  {
    return m_Entries.empty();
  }

  /** "" when `current` has the same entries as this (saved) fingerprint;
   *  otherwise the first difference, in this fingerprint's order, e.g.
   *  "morea_sampling_rate: 0.25 in the checkpoint, 0.5 in this run". */
  std::string
  FirstDifference(const RunFingerprint & current) const;

private:
  std::vector<Entry> m_Entries;
};

/** `value` as text that reads back exactly, as short as that allows ("0.3"). */
std::string
ExactText(double value);

/** Whether a parameter key can change the front: all but bookkeeping
 *  (sweep_descriptor, num_runs, problem_id, zip), the CUDA device
 *  (cuda_gpu_id, cuda_compute_level), ea_num_generations (a resumed run may
 *  go on for longer) and evaluation_border_margin. */
bool
ParameterChangesTheFront(const std::string & key);
} // namespace morea_core

#endif
