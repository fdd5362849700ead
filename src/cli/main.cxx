// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The `morea` command line: multi-objective deformable registration (MOREA).
#include "CommandCommon.h"
#include "CrashReport.h"

#include "itkMacro.h"
#include "morea_core/Error.h"

#include <iostream>

int
main(int argc, char ** argv)
{
  morea_cli::InstallCrashReport();
  CLI::App app{ "morea: multi-objective deformable registration of 3D images with large deformations" };
  app.require_subcommand(1);
  app.set_version_flag("--version", "morea 0.1.0");
  morea_cli::AddPhantomCommand(app);
  morea_cli::AddPreprocessCommand(app);
  morea_cli::AddEvaluateCommand(app);
  morea_cli::AddMeshCommand(app);
  morea_cli::AddRegisterCommand(app);
  morea_cli::AddDemoCommand(app);
  morea_cli::AddBenchmarkCommand(app);
  morea_cli::AddInfoCommand(app);
  morea_cli::AddParametersCommand(app);
  morea_cli::AddBatchCommand(app);
  morea_cli::AddViewCommand(app);
  try
  {
    app.parse(argc, argv);
  }
  catch (const CLI::ParseError & e)
  {
    return app.exit(e);
  }
  catch (const itk::ExceptionObject & e)
  {
    std::cerr << "morea: error: " << e.GetDescription() << "\n";
    return 1;
  }
  catch (const std::exception & e)
  {
    std::cerr << "morea: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
