// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "FilterRun.h"

#include "itkCommand.h"
#include "itkTransformFileReader.h"
#include "morea_core/Error.h"
#include "morea_core/ThreadPool.h"

#include <algorithm>

namespace morea_cli
{
using namespace morea_core;

namespace
{
using PointSetType = RegistrationFilterType::PointSetType;

PointSetType::Pointer
ToPointSet(const itk::morea::PointListType & points)
{
  if (points.empty())
    return nullptr;
  auto set = PointSetType::New();
  auto container = PointSetType::PointsContainer::New();
  container->Reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    PointSetType::PointType p;
    for (unsigned d = 0; d < 3; ++d)
      p[d] = static_cast<float>(points[i][d]);
    container->SetElement(i, p);
  }
  set->SetPoints(container);
  return set;
}
} // namespace

RegistrationFilterType::Pointer
MakeRegistrationFilter(const itk::morea::RegistrationProblem & problem, const ParameterSet & parameters,
                       const FilterSettings & settings)
{
  auto filter = RegistrationFilterType::New();
  filter->SetFixedImage(problem.fixedImage);
  filter->SetMovingImage(problem.movingImage);
  for (const auto & s : problem.structures)
  {
    if (s.fixedMask || s.movingMask)
      filter->AddStructure(s.name, s.fixedMask, s.movingMask);
    const auto fixedPoints = ToPointSet(s.fixedPoints);
    const auto movingPoints = ToPointSet(s.movingPoints);
    if (fixedPoints || movingPoints)
      filter->AddStructurePoints(s.name, fixedPoints, movingPoints);
  }
  filter->SetFixedBodyMask(problem.fixedBodyMask);
  filter->SetMovingBodyMask(problem.movingBodyMask);
  filter->SetFixedLandmarks(ToPointSet(problem.fixedLandmarks));
  filter->SetMovingLandmarks(ToPointSet(problem.movingLandmarks));
  filter->SetParameters(parameters);
  filter->SetBackend(settings.backend);
  filter->SetNumberOfWorkUnits(static_cast<itk::ThreadIdType>(
    settings.threads ? settings.threads : morea_core::HostThreads()));
  filter->SetRefusalBounds(settings.refusalBounds);
  filter->SetSelection(settings.selection);
  filter->SetCheckpointFile(settings.checkpointFile);
  filter->SetCheckpointInterval(settings.checkpointInterval);
  filter->SetCheckpointSeconds(settings.checkpointSeconds);
  filter->SetResume(settings.resume);
  filter->SetInitialMovingTransform(settings.initialTransform);
  if (settings.onGeneration)
  {
    RegistrationFilterType * f = filter.GetPointer(); // the filter owns the observer: no cycle
    filter->AddObserver(itk::IterationEvent(), [f, onGeneration = settings.onGeneration](const itk::EventObject &) {
      onGeneration(f->GetLastGenerationRecord(), f->GetNumberOfGenerations());
    });
  }
  return filter;
}

RegistrationFilterType::InitialTransformType::Pointer
ReadTransformFile(const std::string & path)
{
  auto reader = itk::TransformFileReaderTemplate<double>::New();
  reader->SetFileName(path);
  try
  {
    reader->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    throw Error("cannot read the transform file '" + path + "': " + e.GetDescription());
  }
  const auto * list = reader->GetTransformList();
  if (list->size() != 1)
    throw Error("the transform file '" + path + "' holds " + std::to_string(list->size()) +
                " transforms; one linear transform is needed");
  return list->front();
}

void
UpdateRegistrationFilter(RegistrationFilterType & filter)
{
  try
  {
    filter.Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    throw Error(itk::morea::UserMessage(e.GetDescription()));
  }
}
} // namespace morea_cli
