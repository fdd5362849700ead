// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The CLI's one way to register: a loaded problem handed to
// itk::MultiObjectiveMeshRegistrationFilter (`morea register`, `morea demo`).
#ifndef morea_cli_FilterRun_h
#define morea_cli_FilterRun_h

#include "itkMultiObjectiveMeshRegistrationFilter.h"
#include "itkRegistrationProblem.h"
#include "morea_core/ParameterSet.h"

#include <functional>
#include <string>

namespace morea_cli
{
using RegistrationFilterType = itk::MultiObjectiveMeshRegistrationFilter<itk::morea::ImageType, itk::morea::ImageType>;

/** The filter's settings besides the problem and the parameters. */
struct FilterSettings
{
  std::string backend{ "auto" };
  std::size_t threads{ 0 }; ///< 0: all hardware threads
  std::string refusalBounds{ "auto" };
  std::string selection{ "best-guidance,knee" };
  std::string checkpointFile; ///< empty: none
  std::size_t checkpointInterval{ 0 }; ///< generations; 0: none
  double      checkpointSeconds{ 0.0 }; ///< 0: none
  bool        resume{ false };
  /** Pre-alignment given instead of the rigid step; null: none. */
  RegistrationFilterType::InitialTransformType::ConstPointer initialTransform;
  /** After each generation run (not the ones restored from a checkpoint). */
  std::function<void(const morea_core::GenerationRecord &, std::size_t generations)> onGeneration;
};

/** A filter with `problem`'s images, structures (masks and points), body
 *  masks and landmarks as its inputs, and `parameters` and `settings` set;
 *  not yet updated. */
RegistrationFilterType::Pointer
MakeRegistrationFilter(const itk::morea::RegistrationProblem & problem, const morea_core::ParameterSet & parameters,
                       const FilterSettings & settings);

/** The one transform in an ITK transform file (.tfm, .txt, .h5, ANTs .mat);
 *  throws morea_core::Error naming the file otherwise. */
RegistrationFilterType::InitialTransformType::Pointer
ReadTransformFile(const std::string & path);

/** Updates the filter; its ITK exceptions become morea_core::Error with the
 *  filter's description (no source location), as the CLI prints them. */
void
UpdateRegistrationFilter(RegistrationFilterType & filter);
} // namespace morea_cli

#endif
