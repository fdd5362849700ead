// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: one evaluation of a registration result.
 *
 *  Scores a fixed-to-moving displacement field (identity when absent: the
 *  baseline after preprocessing) on a loaded problem with the metrics of
 *  itkRegistrationMetrics.h, leaving out a border margin.
 *=========================================================================*/
#ifndef itkRegistrationEvaluation_h
#define itkRegistrationEvaluation_h

#include "itkRegistrationMetrics.h"
#include "itkRegistrationProblem.h"

#include <string>
#include <vector>

namespace itk
{
namespace morea
{
struct StructureScores
{
  std::string name;
  double      dice{ 0.0 };
  double      hausdorff{ 0.0 };
  double      hausdorff95{ 0.0 };
  double      meanSurfaceDistance{ 0.0 };
};

struct EvaluationScores
{
  std::vector<StructureScores> structures; ///< those with masks on both images
  bool                         hasLandmarks{ false };
  LandmarkErrorScores          landmarks;        ///< pairs whose fixed landmark lies in the fixed image domain
  std::size_t                  landmarksOutside{ 0 }; ///< pairs left out: fixed landmark outside the domain
  double                       nonPositiveJacobianFraction{ 0.0 };
  bool                         hasInverse{ false };
  InverseConsistencyScores     inverseConsistency;
  double                       borderMargin{ 0.0 };
};

/** A zero displacement field on `grid`. */
DisplacementFieldType::Pointer
MakeIdentityField(const ImageBase<Dimension> * grid);

/** Scores `fixedToMoving` (on the fixed grid; null = identity). Structures are
 *  compared on the fixed grid: the fixed mask against the warped moving mask.
 *  `movingToFixed` (on the moving grid), when given, adds inverse consistency. */
EvaluationScores
EvaluateRegistration(const RegistrationProblem &   problem,
                     const DisplacementFieldType * fixedToMoving,
                     const DisplacementFieldType * movingToFixed,
                     double                        borderMargin);

} // namespace morea
} // namespace itk

#endif
