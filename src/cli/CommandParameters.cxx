// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea parameters`: every parameter key with its type, default, range and
// meaning, from the parameter table itself (docs/parameters.md is its output).
#include "CommandCommon.h"

#include <cmath>
#include <iostream>
#include <sstream>

namespace morea_cli
{
namespace
{
std::string
NumberText(double v)
{
  if (std::isinf(v))
    return v > 0 ? "inf" : "-inf";
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string
DefaultText(const ParameterSpec & spec)
{
  return std::visit(
    [](const auto & v) -> std::string {
      using T = std::decay_t<decltype(v)>;
      if constexpr (std::is_same_v<T, bool>)
        return v ? "true" : "false";
      else if constexpr (std::is_same_v<T, std::string>)
        return "\"" + v + "\"";
      else
        return NumberText(static_cast<double>(v));
    },
    spec.defaultValue);
}

std::string
AcceptsText(const ParameterSpec & spec)
{
  using Type = ParameterSpec::Type;
  switch (spec.type)
  {
    case Type::Bool:
      return "true, false";
    case Type::Integer:
    case Type::Real:
      return "[" + NumberText(spec.minimum) + ", " + NumberText(spec.maximum) + "]" +
             (spec.type == Type::Integer ? " integer" : "");
    case Type::String:
    {
      if (spec.choices.empty())
        return "text";
      std::string text;
      for (const auto & c : spec.choices)
        text += (text.empty() ? "" : ", ") + ("`" + c + "`");
      return text;
    }
  }
  return {};
}
} // namespace

void
AddParametersCommand(CLI::App & app)
{
  auto * cmd = app.add_subcommand("parameters", "list every parameter key: default, accepted values, meaning "
                                                "(a Markdown table, as docs/parameters.md holds it)");
  cmd->callback([] {
    std::cout << "| key | default | accepts | meaning |\n|---|---|---|---|\n";
    for (const auto & spec : ParameterSet::Specs())
    {
      std::string meaning = spec.description;
      for (std::size_t p = meaning.find('|'); p != std::string::npos; p = meaning.find('|', p + 2))
        meaning.replace(p, 1, "\\|");
      std::cout << "| `" << spec.key << "` | " << DefaultText(spec) << " | " << AcceptsText(spec) << " | " << meaning
                << " |\n";
    }
  });
}
} // namespace morea_cli
