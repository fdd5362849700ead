// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// `morea view RUN_DIR`: the front navigator page. The folder is checked here;
// the page is served by the Python package (python3 -m morea.view), which
// this command runs in its place.
#include "CommandCommon.h"

#include "itkRegistrationRunFolder.h"
#include "morea_core/Error.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sys/wait.h>
#include <unistd.h>

namespace morea_cli
{
namespace
{
namespace fs = std::filesystem;

/** The folder holding this executable (from /proc), "" when unknown. */
fs::path
ExecutableFolder()
{
  std::error_code ec;
  const auto      self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : self.parent_path();
}

/** Runs `argv` and returns its exit status (-1 when it could not start). */
int
RunQuietly(const std::vector<std::string> & argv)
{
  const pid_t child = fork();
  if (child < 0)
    return -1;
  if (child == 0)
  {
    std::vector<char *> args;
    for (const auto & a : argv)
      args.push_back(const_cast<char *>(a.c_str()));
    args.push_back(nullptr);
    if (std::freopen("/dev/null", "w", stdout) == nullptr || std::freopen("/dev/null", "w", stderr) == nullptr)
      _exit(127);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0)
    if (errno != EINTR)
      return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
} // namespace

void
AddViewCommand(CLI::App & app)
{
  struct Options
  {
    std::string folder;
    std::string host{ "127.0.0.1" };
    int         port{ 8000 };
    bool        open{ false };
  };
  auto   options = std::make_shared<Options>();
  auto * cmd = app.add_subcommand("view", "look through a run's front in a web browser (a local page; needs the "
                                          "Python package morea: MOREA_PYTHON names its interpreter, default python3)");
  cmd->add_option("run", options->folder, "the output folder of a run")->required();
  cmd->add_option("--host", options->host, "address to listen on (default 127.0.0.1: this machine only)");
  cmd->add_option("--port", options->port, "port (0: any free one)")->check(CLI::Range(0, 65535));
  cmd->add_flag("--open", options->open, "open the page in the default web browser");
  cmd->callback([options] {
    // Bad folders are refused here, with the reason, before Python starts.
    itk::morea::CheckRunFolder(options->folder);
    const char *      fromEnvironment = std::getenv("MOREA_PYTHON");
    const std::string python = fromEnvironment && *fromEnvironment ? fromEnvironment : "python3";
    // A build tree keeps the package beside bin/: build/python/morea.
    const fs::path built = ExecutableFolder() / ".." / "python";
    std::error_code ec;
    if (fs::exists(built / "morea" / "view.py", ec))
    {
      const char *      path = std::getenv("PYTHONPATH");
      const std::string value = fs::weakly_canonical(built, ec).string() + (path && *path ? ":" + std::string(path) : "");
      ::setenv("PYTHONPATH", value.c_str(), 1);
    }
    if (RunQuietly({ python, "-c", "import morea.view, morea._morea" }) != 0)
      throw Error("morea view needs the Python package morea (pip install . in the source folder), importable by '" +
                  python + "'; set MOREA_PYTHON to the interpreter that has it");
    std::vector<std::string> argv{ python, "-m", "morea.view", options->folder, "--host", options->host, "--port",
                                   std::to_string(options->port) };
    if (options->open)
      argv.push_back("--open");
    std::vector<char *> args;
    for (auto & a : argv)
      args.push_back(a.data());
    args.push_back(nullptr);
    std::cout.flush();
    execvp(args[0], args.data());
    throw Error("cannot start '" + python + "': " + std::strerror(errno));
  });
}
} // namespace morea_cli
