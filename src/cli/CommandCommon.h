// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Shared pieces of the `morea` subcommands: loading a problem from options or
// a problem folder, parameters, and plain-text output helpers.
#ifndef morea_cli_CommandCommon_h
#define morea_cli_CommandCommon_h

#include "itkRegistrationEvaluation.h"
#include "itkRegistrationProblem.h"
#include "morea_core/ParameterSet.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace morea_cli
{
// The command line speaks the core's vocabulary (ParameterSet, Error, ...).
using namespace morea_core;

/** Options that describe a registration problem on the command line. */
struct ProblemOptions
{
  std::string              folder; ///< a problem folder (layout written by `phantom` and `preprocess`)
  std::string              fixed;
  std::string              moving;
  std::vector<std::string> fixedStructures;  ///< NAME=SOURCE
  std::vector<std::string> movingStructures; ///< NAME=SOURCE
  std::string              fixedBody;
  std::string              movingBody;
  std::string              fixedLandmarks;
  std::string              movingLandmarks;

  void
  AddTo(CLI::App & app);
  /** Loads and validates the problem (folder first, then explicit options on top). */
  itk::morea::RegistrationProblem
  Load() const;
};

/** --parameters FILE, --var NAME=VALUE, --set KEY=VALUE. */
struct ParameterOptions
{
  std::string              file;
  std::vector<std::string> variables;
  std::vector<std::string> overrides;

  void
  AddTo(CLI::App & app);
  ParameterSet
  Load() const;
};


/** Splits "NAME=VALUE"; throws naming `what` when there is no '='. */
std::pair<std::string, std::string>
SplitAssignment(const std::string & text, const std::string & what);

void
WriteJson(const nlohmann::json & json, const std::string & path);

/** A plain-text table of the scores. */
void
PrintScores(std::ostream & out, const itk::morea::EvaluationScores & scores, const std::string & title);

void
AddPhantomCommand(CLI::App & app);
void
AddPreprocessCommand(CLI::App & app);
void
AddEvaluateCommand(CLI::App & app);
void
AddMeshCommand(CLI::App & app);
void
AddRegisterCommand(CLI::App & app);
void
AddDemoCommand(CLI::App & app);
/** `morea benchmark` */
void
AddBenchmarkCommand(CLI::App & app);
void
AddInfoCommand(CLI::App & app);
/** `morea parameters` */
void
AddParametersCommand(CLI::App & app);
/** `morea batch`: runs the Python package's cohort batch */
void
AddBatchCommand(CLI::App & app);
/** `morea view`: the front navigator page of a run's folder. */
void
AddViewCommand(CLI::App & app);
} // namespace morea_cli

#endif
