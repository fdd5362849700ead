// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
//
// `morea batch COHORT.csv ...`: a cohort of registrations run on Dask. The
// Python package runs it (morea.cohort, `python3 -m morea.cohort`); its
// workers run this executable's `morea register`. Every argument after
// `batch` is the Python side's ($MOREA_PYTHON chooses the interpreter).
#include "CommandCommon.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <unistd.h>

namespace morea_cli
{
namespace
{
// Imports the package and runs its command line; a clear message when the
// interpreter lacks it.
constexpr const char * Bootstrap = R"(import sys
try:
    from morea.cohort import main
except ImportError as e:
    sys.stderr.write("morea batch: error: the Python package 'morea' is not importable by " + sys.executable +
                     " (" + str(e) + "); install it (pip install . in the source tree, or pip install morea) or "
                     "set MOREA_PYTHON to a Python that has it\n")
    sys.exit(2)
sys.exit(main(sys.argv[2:], morea=sys.argv[1]))
)";
} // namespace

void
AddBatchCommand(CLI::App & app)
{
  auto * cmd = app.add_subcommand(
    "batch", "run a cohort of registrations (a CSV table, one per row) on Dask: this machine's GPUs or CPUs, a "
             "Slurm/PBS/SGE/LSF cluster or a running scheduler (the Python package morea with dask; `morea batch "
             "--help` lists its options)");
  cmd->prefix_command();
  cmd->set_help_flag(); // --help is the Python side's
  cmd->callback([cmd] {
    const char *       chosen = std::getenv("MOREA_PYTHON");
    const std::string  python = chosen != nullptr && *chosen != '\0' ? chosen : "python3";
    std::error_code    ec;
    const std::string  self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
    std::vector<std::string> words = { python, "-c", Bootstrap, ec ? std::string("morea") : self };
    for (const auto & a : cmd->remaining())
      words.push_back(a);
    std::vector<char *> argv;
    for (auto & w : words)
      argv.push_back(w.data());
    argv.push_back(nullptr);
    std::cout.flush();
    ::execvp(python.c_str(), argv.data());
    throw std::runtime_error("batch: cannot run '" + python + "' (" + std::strerror(errno) +
                             "); install Python 3 with the package morea, or set MOREA_PYTHON");
  });
}
} // namespace morea_cli
