// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  Registers a problem folder (such as the pelvis phantom `morea phantom`
 *  writes) with itk::MultiObjectiveMeshRegistrationFilter in a plain ITK
 *  pipeline: readers, structure masks and landmarks as point sets, an
 *  observer printing progress, the filter, the chosen solution's transforms
 *  written, the moving image and masks resampled onto the fixed grid, and
 *  the Dice of each structure before and after.
 *
 *  Usage: RegisterPelvisPhantom PROBLEM_DIR PARAMETERS.toml OUTPUT_DIR [BACKEND]
 *    PROBLEM_DIR holds fixed.nii.gz, moving.nii.gz, fixed_masks/NAME.nii.gz and
 *    moving_masks/NAME.nii.gz (and optionally fixed_landmarks.txt and
 *    moving_landmarks.txt, elastix point files); BACKEND is auto (default),
 *    cuda, cuda-exact or cpu.
 *=========================================================================*/
#include "itkImageFileReader.h"
#include "itkImageFileWriter.h"
#include "itkImageRegionConstIterator.h"
#include "itkLinearInterpolateImageFunction.h"
#include "itkMultiObjectiveMeshRegistrationFilter.h"
#include "itkResampleImageFilter.h"
#include "itkTransformFileWriter.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using ImageType = itk::Image<float, 3>;
using MaskType = itk::Image<unsigned char, 3>;
using FilterType = itk::MultiObjectiveMeshRegistrationFilter<ImageType, ImageType>;
using PointSetType = FilterType::PointSetType;

template <typename TImage>
typename TImage::Pointer
Read(const std::filesystem::path & path)
{
  return itk::ReadImage<TImage>(path.string());
}

/** FOLDER/STEM with the first image extension found. */
std::filesystem::path
FindImage(const std::filesystem::path & folder, const std::string & stem)
{
  for (const char * extension : { ".nii.gz", ".nii", ".mha", ".mhd", ".nrrd" })
    if (std::filesystem::exists(folder / (stem + extension)))
      return folder / (stem + extension);
  throw std::runtime_error("no image " + (folder / stem).string() + ".{nii.gz,nii,mha,mhd,nrrd}");
}

/** Landmarks from an elastix point file ("point", count, then x y z per line). */
PointSetType::Pointer
ReadLandmarks(const std::string & path)
{
  std::ifstream in(path);
  std::string   kind;
  std::size_t   count = 0;
  in >> kind >> count;
  if (!in || kind != "point")
    throw std::runtime_error("'" + path + "' is not an elastix point file in physical coordinates");
  auto points = PointSetType::New();
  for (std::size_t i = 0; i < count; ++i)
  {
    PointSetType::PointType p;
    in >> p[0] >> p[1] >> p[2];
    if (!in)
      throw std::runtime_error("'" + path + "': fewer points than its header says");
    points->SetPoint(i, p);
  }
  return points;
}

/** The moving mask on the fixed grid through `transform` (linear, inside where >= 0.5). */
MaskType::Pointer
ResampleMask(const MaskType * mask, const ImageType * fixed, const FilterType::CompositeTransformType * transform)
{
  using ResampleType = itk::ResampleImageFilter<MaskType, ImageType, double>;
  auto resample = ResampleType::New();
  resample->SetInput(mask);
  resample->SetTransform(transform);
  resample->SetOutputParametersFromImage(fixed);
  resample->SetDefaultPixelValue(0);
  resample->Update();
  auto out = MaskType::New();
  out->CopyInformation(fixed);
  out->SetRegions(fixed->GetLargestPossibleRegion());
  out->Allocate();
  itk::ImageRegionConstIterator<ImageType> in(resample->GetOutput(), fixed->GetLargestPossibleRegion());
  itk::ImageRegionIterator<MaskType>       o(out, fixed->GetLargestPossibleRegion());
  for (; !in.IsAtEnd(); ++in, ++o)
    o.Set(in.Get() >= 0.5f ? 1 : 0);
  return out;
}

double
Dice(const MaskType * a, const MaskType * b)
{
  std::size_t                             both = 0, na = 0, nb = 0;
  itk::ImageRegionConstIterator<MaskType> ia(a, a->GetLargestPossibleRegion());
  itk::ImageRegionConstIterator<MaskType> ib(b, b->GetLargestPossibleRegion());
  for (; !ia.IsAtEnd(); ++ia, ++ib)
  {
    na += ia.Get() != 0;
    nb += ib.Get() != 0;
    both += ia.Get() != 0 && ib.Get() != 0;
  }
  return na + nb > 0 ? 2.0 * static_cast<double>(both) / static_cast<double>(na + nb) : 1.0;
}
} // namespace

int
main(int argc, char * argv[])
{
  if (argc < 4)
  {
    std::cerr << "usage: " << argv[0] << " PROBLEM_DIR PARAMETERS.toml OUTPUT_DIR [auto|cuda|cuda-exact|cpu]\n";
    return 2;
  }
  namespace fs = std::filesystem;
  const fs::path problem(argv[1]);
  const fs::path output(argv[3]);
  const auto started = std::chrono::steady_clock::now();
  try
  {
    auto fixed = Read<ImageType>(FindImage(problem, "fixed"));
    auto moving = Read<ImageType>(FindImage(problem, "moving"));

    auto filter = FilterType::New();
    filter->SetFixedImage(fixed);
    filter->SetMovingImage(moving);
    filter->SetParameterFile(argv[2]);
    filter->SetBackend(argc > 4 ? argv[4] : "auto");
    filter->SetSelection("best-guidance");

    // Every structure with a mask on both images.
    std::vector<std::string> names;
    for (const auto & entry : fs::directory_iterator(problem / "fixed_masks"))
      names.push_back(entry.path().filename().string().substr(0, entry.path().filename().string().find('.')));
    std::sort(names.begin(), names.end());
    std::vector<std::pair<MaskType::Pointer, MaskType::Pointer>> masks;
    for (const auto & name : names)
    {
      masks.emplace_back(Read<MaskType>(FindImage(problem / "fixed_masks", name)),
                         Read<MaskType>(FindImage(problem / "moving_masks", name)));
      filter->AddStructure(name, masks.back().first, masks.back().second);
    }
    if (fs::exists(problem / "fixed_landmarks.txt") && fs::exists(problem / "moving_landmarks.txt"))
    {
      filter->SetFixedLandmarks(ReadLandmarks((problem / "fixed_landmarks.txt").string()));
      filter->SetMovingLandmarks(ReadLandmarks((problem / "moving_landmarks.txt").string()));
    }

    // Progress: one line per 10 generations.
    filter->AddObserver(itk::IterationEvent(), [&filter](const itk::EventObject &) {
      const auto & r = filter->GetLastGenerationRecord();
      if (r.generation % 10 == 0 || r.generation == filter->GetNumberOfGenerations())
        std::cout << "generation " << r.generation << "/" << filter->GetNumberOfGenerations() << ": front of "
                  << r.archiveSize << ", best guidance " << r.bestGuidance << std::endl;
    });

    filter->Update();
    const auto registered = std::chrono::steady_clock::now();
    std::cout << "registered in " << std::chrono::duration<double>(registered - started).count()
              << " s from reading; evaluated on " << filter->GetBackendUsed()
              << (filter->GetBackendNote().empty() ? "" : " (" + filter->GetBackendNote() + ")") << "\n";

    fs::create_directories(output);
    // The approximation set, one solution per line.
    {
      std::ofstream front(output / "front.csv");
      front.precision(10);
      front << "id,magnitude,intensity,guidance\n";
      for (const auto & s : filter->GetApproximationSet())
        front << s.id << "," << s.objectives[0] << "," << s.objectives[1] << "," << s.objectives[2] << "\n";
    }

    // The chosen solution between the original images, as ITK transform files.
    const auto * forward = filter->GetFixedToMovingTransform(0);
    itk::TransformFileWriterTemplate<double>::Pointer writer = itk::TransformFileWriterTemplate<double>::New();
    writer->SetInput(forward);
    writer->SetFileName((output / "fixed_to_moving.h5").string());
    writer->Update();
    writer->SetInput(filter->GetMovingToFixedTransform(0));
    writer->SetFileName((output / "moving_to_fixed.h5").string());
    writer->Update();

    // The moving image on the fixed grid.
    using ResampleType = itk::ResampleImageFilter<ImageType, ImageType, double>;
    auto resample = ResampleType::New();
    resample->SetInput(moving);
    resample->SetTransform(forward);
    resample->SetOutputParametersFromImage(fixed);
    resample->SetDefaultPixelValue(-1000);
    itk::WriteImage(resample->GetOutput(), (output / "warped_moving.nii.gz").string(), true);

    // The masks: Dice before (identity) and after.
    auto identity = FilterType::CompositeTransformType::New();
    std::cout << "structure   Dice before   Dice after\n";
    for (std::size_t k = 0; k < names.size(); ++k)
    {
      const auto warped = ResampleMask(masks[k].second, fixed, forward);
      itk::WriteImage(warped, (output / ("warped_" + names[k] + ".nii.gz")).string(), true);
      char line[160];
      std::snprintf(line, sizeof line, "%-10s  %11.3f  %11.3f", names[k].c_str(),
                    Dice(masks[k].first, ResampleMask(masks[k].second, fixed, identity)),
                    Dice(masks[k].first, warped));
      std::cout << line << "\n";
    }
    std::cout << "written to " << output.string() << " ("
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()
              << " s from reading to outputs)\n";
  }
  catch (const std::exception & e)
  {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
