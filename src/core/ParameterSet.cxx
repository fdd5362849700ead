// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/ParameterSet.h"

#include "morea_core/Error.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace morea_core
{
namespace
{
using Type = ParameterSpec::Type;
constexpr double kIntMax = 2147483647.0;

ParameterSpec
Int(std::string key, std::int64_t value, double minimum, double maximum, std::string description)
{
  return { std::move(key), Type::Integer, value, minimum, maximum, {}, std::move(description) };
}
ParameterSpec
Real(std::string key, double value, double minimum, double maximum, std::string description)
{
  return { std::move(key), Type::Real, value, minimum, maximum, {}, std::move(description) };
}
ParameterSpec
Bool(std::string key, bool value, std::string description)
{
  return { std::move(key), Type::Bool, value, 0, 0, {}, std::move(description) };
}
ParameterSpec
Text(std::string key, std::string value, std::vector<std::string> choices, std::string description)
{
  return { std::move(key), Type::String, std::move(value), 0, 0, std::move(choices), std::move(description) };
}

std::vector<ParameterSpec>
MakeSpecs()
{
  const double inf = std::numeric_limits<double>::infinity();
  return {
    // Run bookkeeping (paper listing).
    Text("sweep_descriptor", "", {}, "free text naming the experiment"),
    Int("num_runs", 1, 1, 1000, "independent runs with consecutive seeds"),
    Text("problem_id", "", {}, "free text naming the registration problem"),
    Bool("zip", false, "compress the run's output folder"),
    Bool("problem_guidance_enabled", true, "use the structures' contours as the guidance objective"),
    Text("problem_guidance_selection", "-1", {}, "guidance structures: -1 for all, or comma-separated names"),
    Int("cuda_compute_level", 80, 50, 200,
        "lowest CUDA compute capability (x10) a device must have to run the registration (auto: else the CPU)"),
    Int("cuda_gpu_id", 0, 0, 64, "CUDA device ordinal the registration runs on"),
    Int("seed", 0, 0, kIntMax, "random seed of the run"),
    // MO-RV-GOMEA.
    Int("ea_num_generations", 500, 1, 1e7, "generations to run"),
    Int("ea_population_size", 700, 2, 1e7, "solutions in the population"),
    Int("ea_num_clusters", 10, 1, 1000, "clusters (k of k-leader-means)"),
    Int("ea_archive_size", 2000, 1, 1e7, "capacity of the elitist archive"),
    Bool("ea_adaptive_steering_enabled", true, "steer the front towards good guidance"),
    Int("ea_adaptive_steering_activated_at_num_generations", 100, 0, 1e7, "generation steering starts at"),
    Real("ea_adaptive_steering_guidance_threshold", 1.5, 1.0, inf,
         "keep solutions with guidance within this factor of the best"),
    // MOREA model.
    Text("morea_init_noise_method", "global-gaussian", { "global-gaussian", "none" },
         "initial population: fold-free radial-basis deformations, or none"),
    Real("morea_init_noise_factor", 1.0, 0.0, 100.0, "strength of the initial deformations"),
    Text("morea_mesh_generation_method", "annotation-group-random-bladder-10", {},
         "mesh point placement strategy"),
    Int("morea_mesh_num_points", 600, 8, 1e6, "points per mesh"),
    Text("morea_mesh_surface_structures", "bladder", {},
         "structures whose surface constrains the mesh (comma-separated; used by methods naming 'bladder')"),
    Text("morea_mesh_structure_shares", "", {},
         "share of contour points per structure, e.g. \"bladder=2, bones=1\" (unnamed structures: 1)"),
    Text("morea_mesh_shell_offsets", "8, 20", {},
         "distances in mm outside each structure of morea_mesh_shell_structures at which shells of mesh "
         "points are placed (comma-separated, e.g. \"8, 20\"; empty: none)"),
    Text("morea_mesh_shell_structures", "bladder", {},
         "the deforming organs that get shells of mesh points around them (comma-separated)"),
    Real("morea_mesh_shell_fraction", 0.15, 0.0, 0.9, "fraction of the mesh points on the shells, when any"),
    Real("morea_mesh_boundary_fraction", 0.25, 0.0, 1.0,
         "fraction of the random mesh points placed on the domain's faces (they slide within them)"),
    Text("morea_elasticity_factors", "bones=10, bladder=0.5", {},
         "tissue elasticity factors of the deformation magnitude, structure=factor (others: 1)"),
    Text("morea_rigid_structures", "auto", {},
         "structures that keep their shape, guidance or not: \"auto\" (names like bones, femur, femoral head, "
         "sacrum, vertebra, and elasticity factors >= 10), \"none\", or comma-separated names"),
    Real("morea_rigid_weight", 1000.0, 0.0, 1e9,
         "weight of the rigid structures' strain in the deformation magnitude (0: off, the strain limit too)"),
    Real("morea_rigid_strain_limit", 0.0, 0.0, 1.0,
         "largest strain (Frobenius norm of the Green strain's change) a tetrahedron inside a rigid structure may "
         "take; beyond it the solution counts as violating the constraint, like a fold (0: no limit; 0.03 keeps "
         "bones within 0.1 mm at the paper's budget, but slows short runs)"),
    Int("morea_max_num_mesh_levels", 1, 1, 6,
        "mesh resolution levels: after each level but the last the mesh is refined where the images, contours "
        "or strain still disagree, and every solution carries over (1: one mesh throughout)"),
    Int("morea_num_generations_per_level", 0, 0, 1e7,
        "generations of each mesh level but the last, which runs to ea_num_generations (0 with one level)"),
    Real("morea_mesh_refinement_factor", 2.3, 1.0, 20.0,
         "points of each mesh level as a multiple of the level before's"),
    Text("morea_magnitude_metric", "biomechanical", { "biomechanical", "standard" },
         "deformation magnitude: with or without tissue elasticity factors"),
    Text("morea_image_metric", "squared-differences", { "squared-differences" }, "intensity objective"),
    Text("morea_guidance_metric", "continuous-per-group", { "continuous-per-group" }, "guidance objective"),
    Real("morea_sampling_rate", 1.0, 1e-6, 1000.0, "intensity samples per voxel volume"),
    Text("morea_fos_type", "edges", { "edges", "coarse-groups" },
         "linkage model (FOS elements): \"edges\" (pairs of neighbouring points) on every mesh level, or "
         "\"coarse-groups\" (edges on the first level; on refined levels connected groups of points, as many as "
         "the level before had elements: fewer candidates, but more of them fold; see bench/results/mesh-levels.md)"),
    Text("morea_symmetry_mode", "transform-both", { "transform-both" }, "objectives in both directions"),
    Text("morea_dual_dynamic_mode", "dual", { "dual" }, "both meshes' points are variables"),
    Text("morea_repair_method", "gaussian", { "gaussian", "none" }, "repair of folded solutions"),
    Real("morea_fold_volume_fraction", 0.0, 0.0, 0.99,
         "a tetrahedron also counts as folded when its volume leaves [f, 1/f] times its base volume (0: sign only)"),
    Text("morea_ams_strategy", "none", { "none" }, "anticipated mean shift variant"),
    Int("morea_num_disruption_kernels", 0, 0, 0, "disruption kernels (not used by MOREA)"),
    Int("morea_disruption_frequency", 0, 0, 0, "disruption frequency (not used by MOREA)"),
    // Preprocessing (SPEC 4.1).
    Real("preprocess_isotropic_spacing", 1.5, 0.1, 20.0, "isotropic voxel size in mm"),
    Text("preprocess_rigid_structure", "bones", {}, "structure for rigid pre-alignment; \"none\" to skip"),
    Text("preprocess_crop_structure", "", {}, "structure whose bounding box is cropped to; empty: largest-deforming"),
    Real("preprocess_crop_margin", 30.0, 0.0, 1000.0, "margin around the crop structure in mm"),
    Real("preprocess_intensity_min", -1000.0, -1e6, 1e6, "window minimum (maps to 0)"),
    Real("preprocess_intensity_max", 1000.0, -1e6, 1e6, "window maximum (maps to 1)"),
    Real("preprocess_fov_threshold", -1024.0, -1e6, 1e6, "raw values below this are outside the field of view"),
    // Evaluation (SPEC 7).
    Real("evaluation_border_margin", 15.0, 0.0, 1000.0, "border margin in mm left out of metrics"),
  };
}

// A TOML basic string. Control characters are escaped (TOML forbids them raw);
// with `forToml`, '$' is written as \u0024 so that reading the text back does
// not take it for a placeholder.
std::string
Quote(const std::string & s, bool forToml = false)
{
  std::string out = "\"";
  for (char c : s)
  {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += c;
    }
    else if (c == '\n')
      out += "\\n";
    else if (c == '\r')
      out += "\\r";
    else if (c == '\t')
      out += "\\t";
    else if (u < 0x20 || u == 0x7F || (forToml && c == '$'))
    {
      static const char * hex = "0123456789ABCDEF";
      out += "\\u00";
      out += hex[u >> 4];
      out += hex[u & 0xF];
    }
    else
      out += c;
  }
  return out + "\"";
}

std::string
ValueText(const ParameterValue & v, bool forToml = false)
{
  std::ostringstream os;
  std::visit(
    [&os, forToml](const auto & x) {
      using T = std::decay_t<decltype(x)>;
      if constexpr (std::is_same_v<T, bool>)
        os << (x ? "true" : "false");
      else if constexpr (std::is_same_v<T, std::string>)
        os << Quote(x, forToml);
      else if constexpr (std::is_same_v<T, double>)
      {
        os.precision(17);
        os << x;
        if (std::floor(x) == x && std::abs(x) < 1e15)
          os << ".0";
      }
      else
        os << x;
    },
    v);
  return os.str();
}

std::string
TypeName(Type t)
{
  switch (t)
  {
    case Type::Bool:
      return "a boolean";
    case Type::Integer:
      return "an integer";
    case Type::Real:
      return "a number";
    case Type::String:
      return "a string";
  }
  return "?";
}
} // namespace

const std::vector<ParameterSpec> &
ParameterSet::Specs()
{
  static const std::vector<ParameterSpec> specs = MakeSpecs();
  return specs;
}

const ParameterSpec &
ParameterSet::Spec(const std::string & key)
{
  for (const auto & spec : Specs())
  {
    if (spec.key == key)
    {
      return spec;
    }
  }
  // Suggest the closest known key: most typos differ by a few characters.
  std::string best;
  std::size_t bestScore = 0;
  for (const auto & spec : Specs())
  {
    std::size_t common = 0;
    while (common < key.size() && common < spec.key.size() && key[common] == spec.key[common])
    {
      ++common;
    }
    if (common > bestScore)
    {
      bestScore = common;
      best = spec.key;
    }
  }
  std::string message = "unknown parameter '" + key + "'";
  if (bestScore >= 4)
  {
    message += " (did you mean '" + best + "'?)";
  }
  throw Error(message);
}

ParameterSet::ParameterSet()
{
  for (const auto & spec : Specs())
  {
    m_Values[spec.key] = spec.defaultValue;
  }
}

void
ParameterSet::Set(const ParameterSpec & spec, ParameterValue value, const std::string & where)
{
  const std::string prefix = where + ": parameter '" + spec.key + "' ";
  if (spec.type == Type::Real && std::holds_alternative<std::int64_t>(value))
  {
    value = static_cast<double>(std::get<std::int64_t>(value)); // "1" is a fine real
  }
  const bool typeOk = (spec.type == Type::Bool && std::holds_alternative<bool>(value)) ||
                      (spec.type == Type::Integer && std::holds_alternative<std::int64_t>(value)) ||
                      (spec.type == Type::Real && std::holds_alternative<double>(value)) ||
                      (spec.type == Type::String && std::holds_alternative<std::string>(value));
  if (!typeOk)
  {
    throw Error(prefix + "must be " + TypeName(spec.type) + ", got " + ValueText(value));
  }
  if (spec.type == Type::Integer || spec.type == Type::Real)
  {
    const double x = spec.type == Type::Integer ? static_cast<double>(std::get<std::int64_t>(value))
                                                : std::get<double>(value);
    if (!(x >= spec.minimum && x <= spec.maximum))
    {
      std::ostringstream os;
      os << prefix << "is " << ValueText(value) << ", must be in [" << spec.minimum << ", " << spec.maximum << "]";
      throw Error(os.str());
    }
  }
  if (spec.type == Type::String && !spec.choices.empty())
  {
    const auto & s = std::get<std::string>(value);
    if (std::find(spec.choices.begin(), spec.choices.end(), s) == spec.choices.end())
    {
      std::string list;
      for (const auto & c : spec.choices)
      {
        list += (list.empty() ? "" : ", ") + Quote(c);
      }
      throw Error(prefix + "is " + Quote(s) + ", must be one of " + list);
    }
  }
  m_Values[spec.key] = std::move(value);
  m_Explicit[spec.key] = true;
}

std::string
SubstitutePlaceholders(const std::string & text, const std::map<std::string, std::string> & variables,
                       const std::string & sourceName)
{
  std::string out;
  out.reserve(text.size());
  bool inString = false;  // "basic string": backslash escapes
  bool inLiteral = false; // 'literal string': no escapes
  bool inComment = false;
  int  line = 1;
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    const char c = text[i];
    if (c == '\n')
    {
      ++line;
      inComment = false;
      inString = false;
      inLiteral = false;
    }
    else if (!inComment && !inString && c == '\'')
    {
      inLiteral = !inLiteral;
    }
    else if (inLiteral)
    {
    }
    else if (inString && c == '\\' && i + 1 < text.size() && text[i + 1] != '\n')
    {
      // An escape pair ("\\", "\"", ...): copy both characters, neither ends the string.
      out += c;
      out += text[++i];
      continue;
    }
    else if (!inComment && c == '"')
    {
      inString = !inString;
    }
    else if (!inString && c == '#')
    {
      inComment = true;
    }
    if (c == '$' && !inComment)
    {
      std::size_t j = i + 1;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_'))
      {
        ++j;
      }
      const std::string name = text.substr(i + 1, j - i - 1);
      if (!name.empty())
      {
        const auto it = variables.find(name);
        if (it == variables.end())
        {
          throw Error(sourceName + " line " + std::to_string(line) + ": placeholder '$" + name +
                      "' has no value (pass it as --var " + name + "=VALUE)");
        }
        out += it->second;
        i = j - 1;
        continue;
      }
    }
    out += c;
  }
  return out;
}

ParameterSet
ParameterSet::FromToml(const std::string & text, const std::map<std::string, std::string> & variables,
                       const std::string & sourceName)
{
  const std::string substituted = SubstitutePlaceholders(text, variables, sourceName);
  toml::table       table;
  try
  {
    table = toml::parse(substituted, sourceName);
  }
  catch (const toml::parse_error & e)
  {
    std::ostringstream os;
    os << sourceName << " line " << e.source().begin.line << ": " << e.description();
    throw Error(os.str());
  }
  ParameterSet result;
  for (const auto & [key, node] : table)
  {
    const std::string k(key.str());
    const std::string where = sourceName + " line " + std::to_string(node.source().begin.line);
    const ParameterSpec * spec = nullptr;
    try
    {
      spec = &Spec(k);
    }
    catch (const Error & e)
    {
      throw Error(where + ": " + e.what());
    }
    ParameterValue value;
    if (auto b = node.as_boolean())
      value = b->get();
    else if (auto n = node.as_integer())
      value = static_cast<std::int64_t>(n->get());
    else if (auto r = node.as_floating_point())
      value = r->get();
    else if (auto s = node.as_string())
      value = s->get();
    else
      throw Error(where + ": parameter '" + k + "' must be " + TypeName(spec->type) + ", not a table or array");
    result.Set(*spec, std::move(value), where);
  }
  return result;
}

ParameterSet
ParameterSet::FromFile(const std::string & path, const std::map<std::string, std::string> & variables)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw Error("cannot open parameter file '" + path + "'");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return FromToml(text.str(), variables, path);
}

void
ParameterSet::SetFromString(const std::string & key, const std::string & value)
{
  const auto & spec = Spec(key);
  const std::string where = "--set " + key;
  ParameterValue    parsed;
  switch (spec.type)
  {
    case Type::Bool:
      if (value == "true" || value == "1")
        parsed = true;
      else if (value == "false" || value == "0")
        parsed = false;
      else
        throw Error(where + ": expected true or false, got '" + value + "'");
      break;
    case Type::Integer:
    {
      std::size_t used = 0;
      try
      {
        parsed = static_cast<std::int64_t>(std::stoll(value, &used));
      }
      catch (const std::exception &)
      {
        used = 0;
      }
      if (used != value.size() || value.empty())
        throw Error(where + ": expected an integer, got '" + value + "'");
      break;
    }
    case Type::Real:
    {
      std::size_t used = 0;
      try
      {
        parsed = std::stod(value, &used);
      }
      catch (const std::exception &)
      {
        used = 0;
      }
      if (used != value.size() || value.empty())
        throw Error(where + ": expected a number, got '" + value + "'");
      break;
    }
    case Type::String:
      parsed = value;
      break;
  }
  Set(spec, std::move(parsed), where);
}

bool
ParameterSet::GetBool(const std::string & key) const
{
  Spec(key);
  return std::get<bool>(m_Values.at(key));
}
std::int64_t
ParameterSet::GetInteger(const std::string & key) const
{
  Spec(key);
  return std::get<std::int64_t>(m_Values.at(key));
}
double
ParameterSet::GetReal(const std::string & key) const
{
  Spec(key);
  return std::get<double>(m_Values.at(key));
}
const std::string &
ParameterSet::GetString(const std::string & key) const
{
  Spec(key);
  return std::get<std::string>(m_Values.at(key));
}

bool
ParameterSet::IsExplicit(const std::string & key) const
{
  return m_Explicit.count(key) > 0;
}

std::string
ParameterSet::ToToml() const
{
  std::ostringstream os;
  for (const auto & spec : Specs())
  {
    os << spec.key << " = " << ValueText(m_Values.at(spec.key), true) << "\n";
  }
  return os.str();
}

namespace
{
std::string
Trim(const std::string & s)
{
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos)
    return {};
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}
} // namespace

std::vector<std::string>
ParseNameList(const std::string & text)
{
  std::vector<std::string> names;
  std::stringstream        in(text);
  std::string              item;
  while (std::getline(in, item, ','))
  {
    item = Trim(item);
    if (!item.empty())
      names.push_back(item);
  }
  return names;
}

std::vector<std::pair<std::string, double>>
ParseNamedValues(const std::string & text, const std::string & key)
{
  std::vector<std::pair<std::string, double>> result;
  for (const std::string & item : ParseNameList(text))
  {
    const auto eq = item.find('=');
    const std::string name = eq == std::string::npos ? std::string{} : Trim(item.substr(0, eq));
    const std::string value = eq == std::string::npos ? std::string{} : Trim(item.substr(eq + 1));
    char *            end = nullptr;
    const double      v = value.empty() ? 0.0 : std::strtod(value.c_str(), &end);
    if (name.empty() || value.empty() || end == nullptr || *end != '\0' || !std::isfinite(v))
    {
      throw Error("parameter " + key + ": \"" + item + "\" is not of the form name=number");
    }
    result.emplace_back(name, v);
  }
  return result;
}

} // namespace morea_core
