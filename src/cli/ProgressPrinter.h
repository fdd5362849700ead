// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The terminal progress line of `morea register` and `morea demo`.
#ifndef morea_cli_ProgressPrinter_h
#define morea_cli_ProgressPrinter_h

#include "morea_core/MoRvGomea.h"

#include <functional>

namespace morea_cli
{
/** A terminal progress line per generation (a bar on a terminal, every 10th
 *  generation otherwise). */
std::function<void(const morea_core::GenerationRecord &, std::size_t)>
ProgressPrinter();
} // namespace morea_cli

#endif
