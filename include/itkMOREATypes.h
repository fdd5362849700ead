// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: shared ITK types of the module's ITK layer.
 *
 *  The ITK layer works on one set of concrete types so that the heavy ITK
 *  templates are instantiated once, in the library, not in every client.
 *=========================================================================*/
#ifndef itkMOREATypes_h
#define itkMOREATypes_h

#include "itkImage.h"
#include "itkPoint.h"
#include "itkVector.h"

#include <string>
#include <vector>

namespace itk
{
namespace morea
{
constexpr unsigned int Dimension = 3;

/** Intensity images (CT in HU before preprocessing, [0,1] after). */
using ImageType = Image<float, Dimension>;
/** Binary structure masks: 0 outside, 1 inside. */
using MaskType = Image<unsigned char, Dimension>;
/** Label maps: 0 background, one integer per structure. */
using LabelMapType = Image<unsigned short, Dimension>;
/** Dense displacement fields in mm, physical (LPS) components. */
using DisplacementVectorType = Vector<double, Dimension>;
using DisplacementFieldType = Image<DisplacementVectorType, Dimension>;

using PointType = Point<double, Dimension>;
using PointListType = std::vector<PointType>;

/** Physical landmarks in mm, in file order. */
using LandmarkListType = PointListType;

} // namespace morea
} // namespace itk

#endif
