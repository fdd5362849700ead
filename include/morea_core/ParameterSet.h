// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// MultiObjectiveRegistration core: the run parameters and their TOML reader.
//
// Keys are the MOREA paper's parameter-file keys (appendix A listing) plus the
// preprocessing keys of this module. Unknown keys, wrong types and values out
// of range are errors; `$name` placeholders are substituted before parsing.
#ifndef morea_ParameterSet_h
#define morea_ParameterSet_h

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <utility>
#include <vector>

namespace morea_core
{
using ParameterValue = std::variant<bool, std::int64_t, double, std::string>;

/** What one key accepts. */
struct ParameterSpec
{
  enum class Type
  {
    Bool,
    Integer,
    Real,
    String
  };
  std::string              key;
  Type                     type{ Type::Integer };
  ParameterValue           defaultValue;
  double                   minimum{ 0.0 }; ///< for Integer and Real, inclusive
  double                   maximum{ 0.0 }; ///< for Integer and Real, inclusive
  std::vector<std::string> choices;        ///< for String: allowed values (empty: any)
  std::string              description;
};

/** A complete, validated set of parameters: every known key has a value. */
class ParameterSet
{
public:
  /** All defaults (the paper's appendix A parameter file). */
  ParameterSet();

  /** Reads TOML text. `variables` substitute `$name` placeholders (outside comments);
   *  a placeholder without a value is an error. Keys not given keep their defaults.
   *  `sourceName` names the text in error messages. */
  static ParameterSet
  FromToml(const std::string & text, const std::map<std::string, std::string> & variables = {},
           const std::string & sourceName = "parameters");
  static ParameterSet
  FromFile(const std::string & path, const std::map<std::string, std::string> & variables = {});

  /** Sets one key from a string as typed on a command line ("ea_population_size=100"). */
  void
  SetFromString(const std::string & key, const std::string & value);

  bool
  GetBool(const std::string & key) const;
  std::int64_t
  GetInteger(const std::string & key) const;
  double
  GetReal(const std::string & key) const;
  const std::string &
  GetString(const std::string & key) const;

  /** Keys given explicitly (from text or SetFromString), as opposed to defaults. */
  bool
  IsExplicit(const std::string & key) const;

  /** TOML text with every key and its value, one per line, in table order. */
  std::string
  ToToml() const;

  static const std::vector<ParameterSpec> &
  Specs();
  static const ParameterSpec &
  Spec(const std::string & key);

private:
  void
  Set(const ParameterSpec & spec, ParameterValue value, const std::string & where);

  std::map<std::string, ParameterValue> m_Values;
  std::map<std::string, bool>           m_Explicit;
};

/** Replaces `$name` tokens outside TOML comments; throws on a token without a value. */
std::string
SubstitutePlaceholders(const std::string & text, const std::map<std::string, std::string> & variables,
                       const std::string & sourceName);

/** Parses "name=value, name=value" (names without '=' or ','; finite values);
 *  `key` names the parameter in error messages. Empty text gives an empty list. */
std::vector<std::pair<std::string, double>>
ParseNamedValues(const std::string & text, const std::string & key);

/** Splits "a, b, c" into trimmed non-empty names. */
std::vector<std::string>
ParseNameList(const std::string & text);

} // namespace morea_core

#endif
