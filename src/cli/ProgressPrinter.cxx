// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "ProgressPrinter.h"

#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include <unistd.h>

namespace morea_cli
{
std::function<void(const morea_core::GenerationRecord &, std::size_t)>
ProgressPrinter()
{
  const bool terminal = isatty(fileno(stdout)) != 0;
  return [terminal](const morea_core::GenerationRecord & r, std::size_t total) {
    char line[320];
    std::snprintf(line, sizeof line, "generation %zu/%zu  front %zu  best guidance %.4g  hypervolume %.4f  %.2f s",
                  r.generation, total, r.archiveSize, r.bestGuidance, r.hypervolume, r.seconds);
    if (terminal)
    {
      const int width = 24;
      const int done = static_cast<int>(width * static_cast<double>(r.generation) / static_cast<double>(total));
      std::cout << "\r[" << std::string(static_cast<std::size_t>(done), '#')
                << std::string(static_cast<std::size_t>(width - done), '.') << "] " << line << "   " << std::flush;
      if (r.generation == total)
        std::cout << "\n";
    }
    else if (r.generation % 10 == 0 || r.generation == total)
    {
      // Logs also say where the generation's time went.
      const auto & p = r.phaseSeconds;
      std::snprintf(line + std::strlen(line), sizeof line - std::strlen(line),
                    " (evaluation %.2f, folds %.2f, acceptance %.2f, sampling %.2f, modelling %.2f, other %.2f)",
                    p.evaluation, p.foldChecks, p.acceptance, p.sampling, p.modelling, p.bookkeeping);
      if (r.deviceKernelSeconds > 0.0)
        std::snprintf(line + std::strlen(line), sizeof line - std::strlen(line), ", device kernels %.2f s",
                      r.deviceKernelSeconds);
      std::cout << line << "\n" << std::flush;
    }
  };
}

} // namespace morea_cli
