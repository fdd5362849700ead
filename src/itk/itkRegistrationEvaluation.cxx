// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkRegistrationEvaluation.h"

#include "itkMOREAImageIO.h"

namespace itk
{
namespace morea
{
DisplacementFieldType::Pointer
MakeIdentityField(const ImageBase<Dimension> * grid)
{
  auto field = DisplacementFieldType::New();
  field->SetOrigin(grid->GetOrigin());
  field->SetSpacing(grid->GetSpacing());
  field->SetDirection(grid->GetDirection());
  field->SetRegions(grid->GetLargestPossibleRegion());
  field->Allocate();
  field->FillBuffer(DisplacementVectorType(0.0));
  return field;
}

EvaluationScores
EvaluateRegistration(const RegistrationProblem &   problem,
                     const DisplacementFieldType * fixedToMoving,
                     const DisplacementFieldType * movingToFixed,
                     double                        borderMargin)
{
  problem.Validate();
  DisplacementFieldType::Pointer identity;
  if (fixedToMoving == nullptr)
  {
    identity = MakeIdentityField(problem.fixedImage);
    fixedToMoving = identity;
  }
  else if (!SameGrid(fixedToMoving, problem.fixedImage))
  {
    itkGenericExceptionMacro(<< "the fixed-to-moving displacement field is not on the fixed image grid");
  }
  if (movingToFixed != nullptr && !SameGrid(movingToFixed, problem.movingImage))
  {
    itkGenericExceptionMacro(<< "the moving-to-fixed displacement field is not on the moving image grid");
  }

  EvaluationScores scores;
  scores.borderMargin = borderMargin;
  MaskType::Pointer region = borderMargin > 0.0 ? MakeBorderMarginRegion(problem.fixedImage, borderMargin) : nullptr;
  for (const auto & s : problem.structures)
  {
    if (s.fixedMask.IsNull() || s.movingMask.IsNull())
      continue;
    auto            warped = WarpMask(s.movingMask, fixedToMoving);
    StructureScores result;
    result.name = s.name;
    result.dice = ComputeDice(s.fixedMask, warped, region);
    const auto surface = ComputeSurfaceDistances(s.fixedMask, warped, region);
    result.hausdorff = surface.hausdorff;
    result.hausdorff95 = surface.hausdorff95;
    result.meanSurfaceDistance = surface.meanSurfaceDistance;
    scores.structures.push_back(result);
  }
  // Landmarks outside the (possibly cropped) fixed domain have no field value: leave them out, counted.
  LandmarkListType fixedInside, movingInside;
  for (std::size_t i = 0; i < problem.fixedLandmarks.size(); ++i)
  {
    ContinuousIndex<double, Dimension> index;
    problem.fixedImage->TransformPhysicalPointToContinuousIndex(problem.fixedLandmarks[i], index);
    bool inside = true;
    for (unsigned d = 0; d < Dimension; ++d)
      inside = inside && index[d] >= 0.0 &&
               index[d] <= static_cast<double>(problem.fixedImage->GetLargestPossibleRegion().GetSize()[d]) - 1.0;
    if (inside)
    {
      fixedInside.push_back(problem.fixedLandmarks[i]);
      movingInside.push_back(problem.movingLandmarks[i]);
    }
    else
    {
      ++scores.landmarksOutside;
    }
  }
  if (!fixedInside.empty())
  {
    scores.hasLandmarks = true;
    scores.landmarks = ComputeLandmarkErrors(fixedInside, movingInside, identity ? nullptr : fixedToMoving);
  }
  scores.nonPositiveJacobianFraction = ComputeNonPositiveJacobianFraction(fixedToMoving, region);
  if (movingToFixed != nullptr)
  {
    scores.hasInverse = true;
    scores.inverseConsistency = ComputeInverseConsistency(fixedToMoving, movingToFixed, region);
  }
  return scores;
}

} // namespace morea
} // namespace itk
