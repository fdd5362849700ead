// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// A folder archived as one .zip file (the `zip` parameter key).
#ifndef morea_cli_ZipArchive_h
#define morea_cli_ZipArchive_h

#include <string>

namespace morea_cli
{
/** Writes FOLDER.zip beside `folder` with every regular file under it
 *  (deflated, paths relative to the folder's parent, so that unzipping
 *  gives the folder back); written under a temporary name and renamed into
 *  place. Returns the archive's path. Throws morea_core::Error on failure, and
 *  for files of 4 GiB or more (no ZIP64). */
std::string
ZipFolder(const std::string & folder);
} // namespace morea_cli

#endif
