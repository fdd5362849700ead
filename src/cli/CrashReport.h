// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The `morea` command line: a crash says where it happened. A signal that
// ends the process (a fault, an abort from the C library's heap checks or
// from an exception nobody caught) first writes its name and a backtrace to
// standard error, then ends the process with that same signal.
#ifndef morea_cli_CrashReport_h
#define morea_cli_CrashReport_h

namespace morea_cli
{
/** Installs the report for SIGSEGV, SIGBUS, SIGFPE, SIGILL and SIGABRT
 *  (does nothing where the platform has no backtrace). */
void
InstallCrashReport();
} // namespace morea_cli

#endif
