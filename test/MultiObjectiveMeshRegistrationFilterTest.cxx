// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// itk::MultiObjectiveMeshRegistrationFilter on a small synthetic problem: a
// bladder that grows from 8 to 11 mm radius and a bone that stays put.
#include "itkAffineTransform.h"
#include "itkCommand.h"
#include "itkTranslationTransform.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkMultiObjectiveMeshRegistrationFilter.h"
#include "itkRegistrationEvaluation.h"
#include "itkResampleImageFilter.h"
#include "itkTransformFileReader.h"
#include "morea_core/ComputeDevices.h"
#include "morea_core/Error.h"
#include "morea_core/ParetoFront.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <tuple>

using namespace itk::morea;

namespace
{
using FixedImageType = itk::Image<short, 3>;   // cast to float inside the filter
using MovingImageType = itk::Image<float, 3>;  // used as it is
using FilterType = itk::MultiObjectiveMeshRegistrationFilter<FixedImageType, MovingImageType>;

constexpr unsigned N = 32;
constexpr double   Spacing = 2.0;

PointType
BladderCentre()
{
  PointType c;
  c[0] = 1.0;
  c[1] = -1.0;
  c[2] = 1.0;
  return c;
}

PointType
BoneCentre()
{
  PointType c;
  c[0] = 17.0;
  c[1] = 13.0;
  c[2] = -15.0;
  return c;
}

template <typename TImage>
typename TImage::Pointer
MakeGrid()
{
  auto                         image = TImage::New();
  typename TImage::SizeType    size;
  typename TImage::SpacingType spacing;
  typename TImage::PointType   origin;
  size.Fill(N);
  spacing.Fill(Spacing);
  origin.Fill(-31.0); // voxel centres at -31, -29, ..., 31
  image->SetRegions(typename TImage::RegionType(size));
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->Allocate(true);
  return image;
}

/** Soft tissue (40 HU), a contrast-filled bladder (300 HU) and a bone (900 HU). */
template <typename TImage>
typename TImage::Pointer
MakeImage(double bladderRadius)
{
  auto image = MakeGrid<TImage>();
  for (itk::ImageRegionIteratorWithIndex<TImage> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    PointType p;
    image->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    double v = 40.0;
    if (p.EuclideanDistanceTo(BladderCentre()) <= bladderRadius)
      v = 300.0;
    if (p.EuclideanDistanceTo(BoneCentre()) <= 6.0)
      v = 900.0;
    it.Set(static_cast<typename TImage::PixelType>(v));
  }
  return image;
}

MaskType::Pointer
Sphere(const PointType & c, double radius)
{
  auto mask = MakeGrid<MaskType>();
  for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    PointType p;
    mask->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    it.Set(p.EuclideanDistanceTo(c) <= radius ? 1 : 0);
  }
  return mask;
}

struct Problem
{
  FixedImageType::Pointer  fixed = MakeImage<FixedImageType>(8.0);
  MovingImageType::Pointer moving = MakeImage<MovingImageType>(11.0);
  MaskType::Pointer        fixedBladder = Sphere(BladderCentre(), 8.0);
  MaskType::Pointer        movingBladder = Sphere(BladderCentre(), 11.0);
  MaskType::Pointer        fixedBones = Sphere(BoneCentre(), 6.0);
  MaskType::Pointer        movingBones = Sphere(BoneCentre(), 6.0);
};

FilterType::Pointer
MakeFilter(const Problem & problem)
{
  auto filter = FilterType::New();
  filter->SetFixedImage(problem.fixed);
  filter->SetMovingImage(problem.moving);
  filter->AddStructure("bladder", problem.fixedBladder, problem.movingBladder);
  filter->AddStructure("bones", problem.fixedBones, problem.movingBones);
  filter->SetPopulationSize(16);
  filter->SetNumberOfGenerations(6);
  filter->SetSeed(3);
  filter->SetParameter("ea_num_clusters", "2");
  filter->SetParameter("ea_archive_size", "30");
  filter->SetParameter("morea_mesh_num_points", "60");
  filter->SetParameter("morea_sampling_rate", "0.3");
  filter->SetParameter("preprocess_rigid_structure", "none");
  filter->SetParameter("preprocess_isotropic_spacing", "2.0");
  filter->SetNumberOfWorkUnits(2);
  filter->SetBackend("cpu");
  return filter;
}

/** Counts events and remembers the generations and progress they report. */
class Observer : public itk::Command
{
public:
  using Self = Observer;
  using Pointer = itk::SmartPointer<Self>;
  itkNewMacro(Self);

  std::vector<std::size_t> generations;
  std::vector<float>       progress;

  void
  Execute(itk::Object * caller, const itk::EventObject & event) override
  {
    Execute(static_cast<const itk::Object *>(caller), event);
  }
  void
  Execute(const itk::Object * caller, const itk::EventObject & event) override
  {
    const auto * filter = static_cast<const FilterType *>(caller);
    if (itk::IterationEvent().CheckEvent(&event))
    {
      generations.push_back(filter->GetCurrentGeneration());
      EXPECT_EQ(filter->GetLastGenerationRecord().generation, generations.back());
    }
    else if (itk::ProgressEvent().CheckEvent(&event))
      progress.push_back(filter->GetProgress());
  }
};

void
ExpectOnGrid(const DisplacementFieldTransformType * transform, const ImageType * grid)
{
  ASSERT_NE(transform, nullptr);
  const auto * field = transform->GetDisplacementField();
  ASSERT_NE(field, nullptr);
  EXPECT_EQ(field->GetLargestPossibleRegion().GetSize(), grid->GetLargestPossibleRegion().GetSize());
  for (unsigned d = 0; d < 3; ++d)
  {
    EXPECT_NEAR(field->GetOrigin()[d], grid->GetOrigin()[d], 1e-9);
    EXPECT_NEAR(field->GetSpacing()[d], grid->GetSpacing()[d], 1e-9);
  }
}
} // namespace

TEST(MultiObjectiveMeshRegistrationFilter, RegistersASyntheticBladderAndReportsEachGeneration)
{
  const Problem problem;
  auto          filter = MakeFilter(problem);
  filter->SetSelection("best-guidance,knee");
  auto observer = Observer::New();
  filter->AddObserver(itk::IterationEvent(), observer);
  filter->AddObserver(itk::ProgressEvent(), observer);
  ASSERT_NO_THROW(filter->Update());

  // One IterationEvent per generation, in order; progress climbs to 1.
  EXPECT_EQ(observer->generations, (std::vector<std::size_t>{ 1, 2, 3, 4, 5, 6 }));
  // The history also holds the initial population's record (generation 0).
  ASSERT_EQ(filter->GetGenerationHistory().size(), 7u);
  EXPECT_EQ(filter->GetGenerationHistory().front().generation, 0u);
  EXPECT_EQ(filter->GetCurrentGeneration(), 6u);
  ASSERT_FALSE(observer->progress.empty());
  EXPECT_FLOAT_EQ(observer->progress.back(), 1.0f);
  EXPECT_TRUE(std::is_sorted(observer->progress.begin(), observer->progress.end()));

  // The approximation set: non-empty, feasible, mutually non-dominated, by ascending guidance.
  const auto & set = filter->GetApproximationSet();
  ASSERT_FALSE(set.empty());
  for (std::size_t a = 0; a < set.size(); ++a)
  {
    EXPECT_EQ(set[a].constraint, 0.0);
    if (a > 0)
    {
      EXPECT_LE(set[a - 1].objectives[2], set[a].objectives[2]);
    }
    for (std::size_t b = 0; b < set.size(); ++b)
      EXPECT_FALSE(morea_core::Dominates(set[a].objectives, set[b].objectives)) << set[a] << " dominates " << set[b];
  }

  // The chosen solutions: best guidance first, then the knee.
  ASSERT_EQ(filter->GetNumberOfSelectedSolutions(), 2u);
  EXPECT_EQ(filter->GetSelectedSolutionLabel(0), "best_guidance");
  EXPECT_EQ(filter->GetSelectedSolutionLabel(1), "knee");
  std::vector<morea_core::ObjectiveVector> objectives;
  for (const auto & s : set)
    objectives.push_back(s.objectives);
  EXPECT_EQ(filter->GetSelectedSolutionIndex(0), morea_core::SelectBestGuidance(objectives));
  EXPECT_EQ(filter->GetSelectedSolutionIndex(1), morea_core::SelectKnee(objectives));
  EXPECT_THROW(filter->GetFixedToMovingTransform(2), itk::ExceptionObject);

  // Both transforms on the preprocessed grid (one grid: no rigid step, 2 mm already).
  const ImageType * grid = filter->GetPreprocessedFixedImage();
  ASSERT_NE(grid, nullptr);
  ASSERT_NE(filter->GetPreprocessedMovingImage(), nullptr);
  EXPECT_NEAR(grid->GetSpacing()[0], 2.0, 1e-9);
  for (itk::SizeValueType i = 0; i < filter->GetNumberOfSelectedSolutions(); ++i)
  {
    const auto * forward = filter->GetPreprocessedFixedToMovingTransform(i);
    const auto * backward = filter->GetPreprocessedMovingToFixedTransform(i);
    ExpectOnGrid(forward, grid);
    ExpectOnGrid(backward, grid);
    // The bladder grows about its centre, so its centre barely moves.
    PointType near = BladderCentre();
    near[0] += 1.0;
    EXPECT_LT(forward->TransformPoint(near).EuclideanDistanceTo(near), 5.0);
    EXPECT_LT(backward->TransformPoint(near).EuclideanDistanceTo(near), 5.0);
    // Without pre-alignment the original-frame composites map points as the fields do.
    EXPECT_LT(filter->GetFixedToMovingTransform(i)->TransformPoint(near).EuclideanDistanceTo(forward->TransformPoint(near)),
              1e-9);
    EXPECT_LT(
      filter->GetMovingToFixedTransform(i)->TransformPoint(near).EuclideanDistanceTo(backward->TransformPoint(near)),
      1e-9);
  }
  EXPECT_EQ(filter->GetBackendUsed(), "cpu");
  EXPECT_EQ(filter->GetBackendNote(), "");

  // No pre-alignment: the rigid transform is the identity.
  ASSERT_NE(filter->GetRigidTransform(), nullptr);
  EXPECT_LT(filter->GetRigidTransform()->TransformPoint(BoneCentre()).EuclideanDistanceTo(BoneCentre()), 1e-9);
  EXPECT_EQ(filter->GetPreprocessReport().rigidStructure, "");

  std::ostringstream printed;
  filter->Print(printed);
  for (const char * text : { "ea_population_size = 16", "ea_num_generations = 6", "morea_mesh_num_points = 60",
                             "preprocess_rigid_structure", "Selection: best-guidance,knee", "bladder, bones" })
    EXPECT_NE(printed.str().find(text), std::string::npos) << text << " not in\n" << printed.str();
}

TEST(MultiObjectiveMeshRegistrationFilter, ParameterSettersWriteTheParameterSet)
{
  auto filter = FilterType::New();
  filter->SetNumberOfGenerations(12);
  filter->SetPopulationSize(40);
  filter->SetSeed(7);
  EXPECT_EQ(filter->GetParameters().GetInteger("ea_num_generations"), 12);
  EXPECT_EQ(filter->GetNumberOfGenerations(), 12u);
  EXPECT_EQ(filter->GetPopulationSize(), 40u);
  EXPECT_EQ(filter->GetSeed(), 7u);
  EXPECT_TRUE(filter->GetParameters().IsExplicit("seed"));
  EXPECT_EQ(filter->GetSelection(), "best-guidance");
  EXPECT_THROW(filter->SetParameter("no_such_key", "1"), itk::ExceptionObject);
  EXPECT_THROW(filter->SetPopulationSize(1), itk::ExceptionObject); // below the range
  EXPECT_THROW(filter->SetParameterFile("/nonexistent/parameters.toml"), itk::ExceptionObject);
  EXPECT_EQ(filter->GetPopulationSize(), 40u);
}

TEST(MultiObjectiveMeshRegistrationFilter, BadInputsThrowITKExceptions)
{
  const Problem problem;
  {
    // No moving image.
    auto filter = MakeFilter(problem);
    filter->SetMovingImage(nullptr);
    EXPECT_THROW(filter->Update(), itk::ExceptionObject);
  }
  {
    // A structure known on the fixed image only.
    auto filter = MakeFilter(problem);
    filter->AddStructure("rectum", problem.fixedBones, nullptr);
    try
    {
      filter->Update();
      FAIL() << "no exception";
    }
    catch (const itk::ExceptionObject & e)
    {
      EXPECT_NE(std::string(e.GetDescription()).find("rectum"), std::string::npos) << e.GetDescription();
    }
    // Removing it drops both of its named inputs.
    filter->RemoveStructure("rectum");
    EXPECT_EQ(filter->GetStructureNames(), (std::vector<std::string>{ "bladder", "bones" }));
    EXPECT_EQ(filter->GetFixedStructureMask("rectum"), nullptr);
  }
  {
    // A selection typo fails before the run.
    auto filter = MakeFilter(problem);
    filter->SetSelection("best-guidance,kne");
    EXPECT_THROW(filter->Update(), itk::ExceptionObject);
    EXPECT_EQ(filter->GetNumberOfSelectedSolutions(), 0u);
  }
}

TEST(MultiObjectiveMeshRegistrationFilter, SpreadSelectionsNameFewDistinctSolutionsById)
{
  itk::morea::ApproximationSet set;
  for (std::uint64_t id = 0; id < 50; ++id)
  {
    const double t = static_cast<double>(id) / 49.0; // a line from guidance 0 to magnitude 0
    set.push_back({ 100 + id, { { 1.0 - t, 0.5, t } }, 0.0 });
  }
  const auto chosen = itk::morea::SelectSolutions(set, "best-guidance,spread:3,spread:3");
  // Best guidance (id 100) under its own label and again as the spread's
  // first; then the far end and the middle (ids 124 and 125 tie: the first);
  // a repeat adds nothing.
  std::vector<std::string> labels;
  for (const auto & c : chosen)
    labels.push_back(c.label);
  EXPECT_EQ(labels, (std::vector<std::string>{ "best_guidance", "solution_100", "solution_149", "solution_124" }));
  EXPECT_EQ(itk::morea::SelectSolutions(set, "spread:500").size(), set.size());
  for (const char * bad : { "spread:0", "spread:", "spread:-2", "spread:2x", "spread: 2", "spread:1.5" })
    EXPECT_THROW(itk::morea::CheckSolutionSelection(bad), morea_core::Error) << bad;
  EXPECT_NO_THROW(itk::morea::CheckSolutionSelection("knee,spread:12"));
}

TEST(MultiObjectiveMeshRegistrationFilter, AbortsAfterTheGenerationAnObserverStopsAt)
{
  const Problem problem;
  auto          filter = MakeFilter(problem);
  auto          observer = itk::CStyleCommand::New();
  std::vector<std::size_t> generations;
  struct Context
  {
    FilterType *               filter;
    std::vector<std::size_t> * generations;
  } context{ filter.GetPointer(), &generations };
  observer->SetClientData(&context);
  observer->SetCallback([](itk::Object *, const itk::EventObject &, void * data) {
    auto * c = static_cast<Context *>(data);
    c->generations->push_back(c->filter->GetCurrentGeneration());
    if (c->filter->GetCurrentGeneration() == 2)
      c->filter->AbortGenerateDataOn();
  });
  filter->AddObserver(itk::IterationEvent(), observer);
  EXPECT_THROW(filter->Update(), itk::ProcessAborted);
  EXPECT_EQ(generations, (std::vector<std::size_t>{ 1, 2 }));
  EXPECT_EQ(filter->GetNumberOfSelectedSolutions(), 0u);
  EXPECT_TRUE(filter->GetApproximationSet().empty());
}

TEST(MultiObjectiveMeshRegistrationFilter, ResumesFromItsCheckpoint)
{
  const std::string checkpoint = std::string(MOREA_TEST_OUTPUT_DIR) + "/filter_checkpoint.bin";
  std::filesystem::create_directories(MOREA_TEST_OUTPUT_DIR);
  std::filesystem::remove(checkpoint);
  const Problem problem;
  auto          filter = MakeFilter(problem);
  filter->SetCheckpointFile(checkpoint);
  filter->SetCheckpointInterval(3);
  filter->ResumeOn(); // no file yet: starts afresh
  filter->Update();
  EXPECT_EQ(filter->GetResumedAtGeneration(), 0u);
  ASSERT_TRUE(std::filesystem::exists(checkpoint));

  // Two more generations on top of the six written: only those fire events.
  auto observer = Observer::New();
  filter->AddObserver(itk::IterationEvent(), observer);
  filter->SetNumberOfGenerations(8);
  filter->Update();
  EXPECT_EQ(filter->GetResumedAtGeneration(), 6u);
  EXPECT_EQ(observer->generations, (std::vector<std::size_t>{ 7, 8 }));
  EXPECT_EQ(filter->GetCurrentGeneration(), 8u);
  EXPECT_FALSE(filter->GetApproximationSet().empty());
  EXPECT_EQ(filter->GetNumberOfSelectedSolutions(), 1u);
  std::filesystem::remove(checkpoint);
}

namespace
{
/** A problem whose moving image and masks lie `shift` mm away from where
 *  the fixed ones are: the rigid pre-alignment on the bones recovers it. */
struct ShiftedProblem : Problem
{
  explicit ShiftedProblem(const itk::Vector<double, 3> & shift)
  {
    const auto origin = moving->GetOrigin() + shift;
    moving->SetOrigin(origin);
    movingBladder->SetOrigin(origin);
    movingBones->SetOrigin(origin);
  }
};

double
Dice(const MaskType * a, const MaskType * b)
{
  std::size_t both = 0, na = 0, nb = 0;
  itk::ImageRegionConstIterator<MaskType> ia(a, a->GetLargestPossibleRegion());
  itk::ImageRegionConstIterator<MaskType> ib(b, b->GetLargestPossibleRegion());
  for (; !ia.IsAtEnd(); ++ia, ++ib)
  {
    na += ia.Get() != 0;
    nb += ib.Get() != 0;
    both += ia.Get() != 0 && ib.Get() != 0;
  }
  return na + nb ? 2.0 * static_cast<double>(both) / static_cast<double>(na + nb) : 1.0;
}

/** A mask resampled as the scores resample it: linear interpolation, then inside where >= 0.5. */
MaskType::Pointer
ResampleMaskThrough(const MaskType * mask, const itk::ImageBase<3> * grid, const itk::TransformBaseTemplate<double> * t)
{
  using ResampleType = itk::ResampleImageFilter<MaskType, ImageType, double>;
  auto resample = ResampleType::New();
  resample->SetInput(mask);
  resample->SetTransform(dynamic_cast<const ResampleType::TransformType *>(t));
  resample->SetOutputParametersFromImage(grid);
  resample->SetDefaultPixelValue(0);
  resample->Update();
  auto out = MaskType::New();
  out->CopyInformation(resample->GetOutput());
  out->SetRegions(resample->GetOutput()->GetLargestPossibleRegion());
  out->Allocate();
  itk::ImageRegionConstIterator<ImageType> in(resample->GetOutput(), out->GetLargestPossibleRegion());
  itk::ImageRegionIterator<MaskType>       o(out, out->GetLargestPossibleRegion());
  for (; !in.IsAtEnd(); ++in, ++o)
    o.Set(in.Get() >= 0.5f ? 1 : 0);
  return out;
}

itk::PointSet<float, 3>::Pointer
SurfacePointSet(const MaskType * mask)
{
  auto set = itk::PointSet<float, 3>::New();
  std::size_t i = 0;
  for (const auto & p : ExtractSurfacePoints(mask))
  {
    itk::PointSet<float, 3>::PointType q;
    for (unsigned d = 0; d < 3; ++d)
      q[d] = static_cast<float>(p[d]);
    set->SetPoint(i++, q);
  }
  return set;
}

std::string
UpdateError(FilterType * filter)
{
  try
  {
    filter->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    return e.GetDescription();
  }
  return "(no exception)";
}
} // namespace

TEST(MultiObjectiveMeshRegistrationFilter, OriginalFrameTransformsReadBackReproduceTheScores)
{
  itk::Vector<double, 3> shift;
  shift[0] = 4.0;
  shift[1] = -2.0;
  shift[2] = 2.0;
  const ShiftedProblem problem(shift);
  auto                 filter = MakeFilter(problem);
  filter->SetParameter("preprocess_rigid_structure", "bones");
  filter->SetSelection("best-guidance,knee");
  ASSERT_NO_THROW(filter->Update());
  // The pre-alignment found the shift.
  EXPECT_LT(filter->GetRigidTransform()->TransformPoint(BoneCentre()).EuclideanDistanceTo(BoneCentre() + shift), 0.5);

  const auto & run = filter->GetRegistrationRun();
  const std::string dir = std::string(MOREA_TEST_OUTPUT_DIR) + "/filter_original_frame/";
  std::filesystem::create_directories(dir);
  for (itk::SizeValueType i = 0; i < filter->GetNumberOfSelectedSolutions(); ++i)
  {
    // What scores.json holds: the scores in the preprocessed frame.
    const auto & fields = run.selected[i].fields;
    const auto   scores = EvaluateRegistration(run.preprocessed.problem, fields.fixedToMoving, fields.movingToFixed, 0.0);
    // The transforms as `morea register` writes them, read back as any ITK program would.
    WriteSolutionTransforms(run.selected[i].original, dir + "fixed_to_moving.h5", dir + "moving_to_fixed.h5");
    auto reader = itk::TransformFileReaderTemplate<double>::New();
    reader->SetFileName(dir + "fixed_to_moving.h5");
    reader->Update();
    ASSERT_EQ(reader->GetTransformList()->size(), 1u);
    const auto * read = reader->GetTransformList()->front().GetPointer();
    for (const auto & [name, fixedMask, movingMask] :
         { std::make_tuple("bladder", problem.fixedBladder, problem.movingBladder),
           std::make_tuple("bones", problem.fixedBones, problem.movingBones) })
    {
      const auto warped = ResampleMaskThrough(movingMask, fixedMask, read);
      const auto fromMemory = ResampleMaskThrough(movingMask, fixedMask, filter->GetFixedToMovingTransform(i));
      EXPECT_EQ(Dice(warped, fromMemory), 1.0) << name;
      double inScores = -1.0;
      for (const auto & s : scores.structures)
        if (s.name == name)
          inScores = s.dice;
      EXPECT_NEAR(Dice(fixedMask, warped), inScores, 0.01) << name << ", solution " << i;
    }
  }
}

TEST(MultiObjectiveMeshRegistrationFilter, ContourPointsAndLandmarksAsPointSets)
{
  const Problem problem;
  auto          filter = MakeFilter(problem);
  // The moving bladder known by its contour points only (as from an RTSTRUCT).
  filter->RemoveStructure("bladder");
  filter->AddStructure("bladder", problem.fixedBladder, nullptr);
  filter->AddStructurePoints("bladder", nullptr, SurfacePointSet(problem.movingBladder));
  auto fixedLandmarks = itk::PointSet<float, 3>::New();
  auto movingLandmarks = itk::PointSet<float, 3>::New();
  fixedLandmarks->SetPoint(0, BoneCentre());
  movingLandmarks->SetPoint(0, BoneCentre());
  fixedLandmarks->SetPoint(1, BladderCentre());
  movingLandmarks->SetPoint(1, BladderCentre());
  filter->SetFixedLandmarks(fixedLandmarks);
  filter->SetMovingLandmarks(movingLandmarks);
  ASSERT_NO_THROW(filter->Update());
  const auto & pre = filter->GetRegistrationRun().preprocessed.problem;
  const auto * bladder = pre.FindStructure("bladder");
  ASSERT_NE(bladder, nullptr);
  EXPECT_FALSE(bladder->movingPoints.empty());
  EXPECT_EQ(pre.fixedLandmarks.size(), 2u);
  EXPECT_EQ(pre.movingLandmarks.size(), 2u);
  EXPECT_FALSE(filter->GetApproximationSet().empty());
}

TEST(MultiObjectiveMeshRegistrationFilter, BadBackendsPointSetsAndKeysThrowClearly)
{
  const Problem problem;
  auto          filter = MakeFilter(problem);
  EXPECT_THROW(filter->SetBackend("gpu"), itk::ExceptionObject);
  EXPECT_EQ(filter->GetBackend(), "cpu");
  {
    // A device that does not exist, named on purpose: refused for CUDA and auto alike.
    auto f = MakeFilter(problem);
    f->SetDevice(63);
    for (const char * backend : { "cuda", "cuda-exact", "auto" })
    {
      f->SetBackend(backend);
      EXPECT_NE(UpdateError(f).find("CUDA device 63"), std::string::npos) << backend << ": " << UpdateError(f);
    }
  }
  {
    auto f = MakeFilter(problem);
    f->AddStructurePoints("rectum", itk::PointSet<float, 3>::New(), SurfacePointSet(problem.movingBones));
    EXPECT_NE(UpdateError(f).find("the fixed point set is empty"), std::string::npos) << UpdateError(f);
    EXPECT_THROW(f->AddStructurePoints("rectum", nullptr, nullptr), itk::ExceptionObject);
  }
  {
    auto f = MakeFilter(problem);
    auto one = itk::PointSet<float, 3>::New();
    one->SetPoint(0, BoneCentre());
    f->SetFixedLandmarks(one);
    f->SetMovingLandmarks(itk::PointSet<float, 3>::New());
    EXPECT_NE(UpdateError(f).find("landmarks: 1 fixed and 0 moving"), std::string::npos) << UpdateError(f);
  }
  for (const auto & [key, value, fragment] : { std::make_tuple("num_runs", "3", "num_runs = 3"),
                                               std::make_tuple("zip", "true", "zip = true") })
  {
    auto f = MakeFilter(problem);
    f->SetParameter(key, value);
    EXPECT_NE(UpdateError(f).find(fragment), std::string::npos) << UpdateError(f);
  }
}

TEST(MultiObjectiveMeshRegistrationFilter, RunsOnTheGpuByDefaultWhenOneIsPresent)
{
  const Problem problem;
  auto          filter = MakeFilter(problem);
  filter->SetBackend("auto"); // the default
  auto fresh = FilterType::New();
  EXPECT_EQ(fresh->GetBackend(), "auto");
  ASSERT_NO_THROW(filter->Update());
  const std::string unavailable = morea_core::CudaUnavailableReason();
  if (unavailable.empty())
  {
    EXPECT_EQ(filter->GetBackendUsed(), "cuda-texture");
    EXPECT_NE(filter->GetBackendNote().find("texture path"), std::string::npos) << filter->GetBackendNote();
  }
  else
  {
    EXPECT_EQ(filter->GetBackendUsed(), "cpu");
    EXPECT_NE(filter->GetBackendNote().find(unavailable), std::string::npos) << filter->GetBackendNote();
  }
  std::ostringstream printed;
  filter->Print(printed);
  EXPECT_NE(printed.str().find("BackendUsed: " + filter->GetBackendUsed()), std::string::npos) << printed.str();
}

TEST(MultiObjectiveMeshRegistrationFilter, AnInitialMovingTransformReplacesTheRigidStep)
{
  itk::Vector<double, 3> shift;
  shift[0] = 4.0;
  shift[1] = -2.0;
  shift[2] = 2.0;
  const ShiftedProblem problem(shift);
  // A translation (linear, not a matrix-offset transform) and an affine: both pre-align as given.
  auto translation = itk::TranslationTransform<double, 3>::New();
  translation->SetOffset(shift);
  auto affine = itk::AffineTransform<double, 3>::New();
  affine->SetTranslation(shift);
  for (const itk::TransformBaseTemplate<double> * initial :
       { static_cast<const itk::TransformBaseTemplate<double> *>(translation.GetPointer()),
         static_cast<const itk::TransformBaseTemplate<double> *>(affine.GetPointer()) })
  {
    auto filter = MakeFilter(problem);
    filter->SetParameter("preprocess_rigid_structure", "bones"); // not used: the transform given wins
    filter->SetInitialMovingTransform(initial);
    ASSERT_NO_THROW(filter->Update()) << initial->GetNameOfClass();
    EXPECT_EQ(filter->GetPreprocessReport().rigidStructure, "");
    EXPECT_FALSE(filter->GetPreprocessReport().initialTransform.empty());
    EXPECT_LT(filter->GetRigidTransform()->TransformPoint(BoneCentre()).EuclideanDistanceTo(BoneCentre() + shift),
              1e-9);
    // The composites start from it: the bone's centre maps onto the moving bone's.
    EXPECT_LT(filter->GetFixedToMovingTransform(0)->TransformPoint(BoneCentre()).EuclideanDistanceTo(BoneCentre() + shift),
              2.0);
  }
}

TEST(MultiObjectiveMeshRegistrationFilter, InitialTransformsThatCannotPreAlignAreRefused)
{
  const Problem problem;
  {
    auto filter = MakeFilter(problem);
    filter->SetInitialMovingTransform(itk::AffineTransform<double, 2>::New());
    EXPECT_NE(UpdateError(filter).find("maps 2-D points to 2-D points; a 3-D transform is needed"), std::string::npos)
      << UpdateError(filter);
  }
  {
    auto filter = MakeFilter(problem);
    auto field = itk::DisplacementFieldTransform<double, 3>::New();
    filter->SetInitialMovingTransform(field);
    EXPECT_NE(UpdateError(filter).find("is not linear"), std::string::npos) << UpdateError(filter);
  }
  {
    auto filter = MakeFilter(problem);
    auto singular = itk::AffineTransform<double, 3>::New();
    auto matrix = singular->GetMatrix();
    matrix(2, 2) = 0.0;
    singular->SetMatrix(matrix);
    filter->SetInitialMovingTransform(singular);
    EXPECT_NE(UpdateError(filter).find("not invertible"), std::string::npos) << UpdateError(filter);
  }
}
