// itk::MultiObjectiveMeshRegistrationFilter on a small synthetic problem: a
// bladder that grows from 8 to 11 mm radius and a bone that stays put.
#include "itkCommand.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkMultiObjectiveMeshRegistrationFilter.h"
#include "morea/ParetoFront.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

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
  filter->SetNumberOfThreadsToUse(2);
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
      EXPECT_FALSE(::morea::Dominates(set[a].objectives, set[b].objectives)) << set[a] << " dominates " << set[b];
  }

  // The chosen solutions: best guidance first, then the knee.
  ASSERT_EQ(filter->GetNumberOfSelectedSolutions(), 2u);
  EXPECT_EQ(filter->GetSelectedSolutionLabel(0), "best_guidance");
  EXPECT_EQ(filter->GetSelectedSolutionLabel(1), "knee");
  std::vector<::morea::ObjectiveVector> objectives;
  for (const auto & s : set)
    objectives.push_back(s.objectives);
  EXPECT_EQ(filter->GetSelectedSolutionIndex(0), ::morea::SelectBestGuidance(objectives));
  EXPECT_EQ(filter->GetSelectedSolutionIndex(1), ::morea::SelectKnee(objectives));
  EXPECT_THROW(filter->GetFixedToMovingTransform(2), itk::ExceptionObject);

  // Both transforms on the preprocessed grid (one grid: no rigid step, 2 mm already).
  const ImageType * grid = filter->GetPreprocessedFixedImage();
  ASSERT_NE(grid, nullptr);
  ASSERT_NE(filter->GetPreprocessedMovingImage(), nullptr);
  EXPECT_NEAR(grid->GetSpacing()[0], 2.0, 1e-9);
  for (itk::SizeValueType i = 0; i < filter->GetNumberOfSelectedSolutions(); ++i)
  {
    const auto * forward = filter->GetFixedToMovingTransform(i);
    const auto * backward = filter->GetMovingToFixedTransform(i);
    ExpectOnGrid(forward, grid);
    ExpectOnGrid(backward, grid);
    // The bladder grows about its centre, so its centre barely moves.
    PointType near = BladderCentre();
    near[0] += 1.0;
    EXPECT_LT(forward->TransformPoint(near).EuclideanDistanceTo(near), 5.0);
    EXPECT_LT(backward->TransformPoint(near).EuclideanDistanceTo(near), 5.0);
  }

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
