// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/RunFingerprint.h"

#include "morea_core/Hash.h"
#include "morea_core/ParameterSet.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iterator>

namespace morea_core
{
std::string
ExactText(double value)
{
  // The shortest of 15 and 17 digits that reads back as the same double:
  // 0.3, not 0.29999999999999999.
  char text[40];
  std::snprintf(text, sizeof text, "%.15g", value);
  if (std::strtod(text, nullptr) != value)
    std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

namespace
{
/** A value as typed in a parameter file, exact for reals (round trip). */
std::string
ParameterText(const ParameterSet & parameters, const ParameterSpec & spec)
{
  switch (spec.type)
  {
    case ParameterSpec::Type::Bool:
      return parameters.GetBool(spec.key) ? "true" : "false";
    case ParameterSpec::Type::Integer:
      return std::to_string(parameters.GetInteger(spec.key));
    case ParameterSpec::Type::Real:
      return ExactText(parameters.GetReal(spec.key));
    case ParameterSpec::Type::String:
      return "\"" + parameters.GetString(spec.key) + "\"";
  }
  return {};
}

std::string
Shown(const std::string & value)
{
  // Long values (a list of elasticity factors) are cut so the message stays one line.
  return value.size() <= 80 ? value : value.substr(0, 77) + "...";
}
} // namespace

bool
ParameterChangesTheFront(const std::string & key)
{
  // Bookkeeping, where the run goes, how long it goes on, and what is
  // measured afterwards: the front does not depend on them.
  static const char * const others[] = { "sweep_descriptor", "num_runs",         "problem_id",
                                         "zip",              "cuda_compute_level", "cuda_gpu_id",
                                         "ea_num_generations", "evaluation_border_margin" };
  return std::none_of(std::begin(others), std::end(others), [&](const char * k) { return key == k; });
}

void
RunFingerprint::Add(const std::string & key, const std::string & value)
{
  const auto it =
    std::find_if(m_Entries.begin(), m_Entries.end(), [&](const Entry & e) { return e.first == key; });
  if (it != m_Entries.end())
    it->second = value;
  else
    m_Entries.emplace_back(key, value);
}

void
RunFingerprint::AddHash(const std::string & key, const void * data, std::size_t size)
{
  Add(key, "xxh64:" + HashText(Hash64(data, size)));
}

void
RunFingerprint::AddParameters(const ParameterSet & parameters)
{
  for (const ParameterSpec & spec : ParameterSet::Specs())
    if (ParameterChangesTheFront(spec.key))
      Add(spec.key, ParameterText(parameters, spec));
}

void
RunFingerprint::AddEvaluationBackend(const std::string & backendName)
{
  Add("evaluation backend", backendName == "cuda-texture" ? "cuda-texture (the texture units' interpolation)"
                                                          : "cpu or cuda-exact (exact interpolation)");
}

std::string
RunFingerprint::FirstDifference(const RunFingerprint & current) const
{
  const auto find = [](const std::vector<Entry> & entries, const std::string & key) {
    return std::find_if(entries.begin(), entries.end(), [&](const Entry & e) { return e.first == key; });
  };
  for (const Entry & saved : m_Entries)
  {
    const auto now = find(current.m_Entries, saved.first);
    if (now == current.m_Entries.end())
      return saved.first + ": " + Shown(saved.second) + " in the checkpoint, not given in this run";
    if (now->second != saved.second)
      return saved.first + ": " + Shown(saved.second) + " in the checkpoint, " + Shown(now->second) + " in this run";
  }
  for (const Entry & now : current.m_Entries)
    if (find(m_Entries, now.first) == m_Entries.end())
      return now.first + ": not in the checkpoint, " + Shown(now.second) + " in this run";
  return {};
}
} // namespace morea_core
