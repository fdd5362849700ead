// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// The Python binding (module morea._morea): one registration through
// itk::MultiObjectiveMeshRegistrationFilter on numpy arrays with their
// geometry. The package (wrapping/python/morea) turns SimpleITK, itk and
// numpy images into these arrays and the results back into transforms.
#include "itkImportImageContainer.h"
#include "itkMeshTransforms.h"
#include "itkMultiObjectiveMeshRegistrationFilter.h"
#include "itkPhantomImages.h"
#include "itkPreprocessing.h"
#include "itkRTStructureSetIO.h"
#include "itkRegistrationEvaluation.h"
#include "itkRegistrationOutputs.h"
#include "itkRegistrationPlots.h"
#include "itkRegistrationRunFolder.h"
#include "morea_core/CheckpointWriter.h"
#include "morea_core/Error.h"
#include "morea_core/OutputFolderLock.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace py = pybind11;

namespace
{
using ImageType = itk::morea::ImageType;
using MaskType = itk::morea::MaskType;
using FilterType = itk::MultiObjectiveMeshRegistrationFilter<ImageType, ImageType>;
using PointSetType = FilterType::PointSetType;
using FieldType = itk::morea::DisplacementFieldType;

/** An image's geometry as the package passes it: spacing, origin (x, y, z)
 *  and the direction matrix, row-major. */
struct Geometry
{
  std::array<double, 3> spacing{ { 1.0, 1.0, 1.0 } };
  std::array<double, 3> origin{ { 0.0, 0.0, 0.0 } };
  std::array<double, 9> direction{ { 1, 0, 0, 0, 1, 0, 0, 0, 1 } };
};

template <typename TImage>
void
SetGeometry(TImage * image, const Geometry & g)
{
  typename TImage::SpacingType   spacing;
  typename TImage::PointType     origin;
  typename TImage::DirectionType direction;
  for (unsigned r = 0; r < 3; ++r)
  {
    if (!(g.spacing[r] > 0.0))
      throw py::value_error("image spacing must be positive");
    spacing[r] = g.spacing[r];
    origin[r] = g.origin[r];
    for (unsigned c = 0; c < 3; ++c)
      direction(r, c) = g.direction[3 * r + c];
  }
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->SetDirection(direction);
}

Geometry
GeometryOf(const itk::ImageBase<3> * image)
{
  Geometry g;
  for (unsigned r = 0; r < 3; ++r)
  {
    g.spacing[r] = image->GetSpacing()[r];
    g.origin[r] = image->GetOrigin()[r];
    for (unsigned c = 0; c < 3; ++c)
      g.direction[3 * r + c] = image->GetDirection()(r, c);
  }
  return g;
}

/** An ITK image over a C-ordered (z, y, x) array's buffer, without a copy;
 *  the array must outlive the image (the result keeps it). */
template <typename TPixel>
typename itk::Image<TPixel, 3>::Pointer
ImageOverArray(const py::array_t<TPixel, py::array::c_style> & array, const Geometry & geometry, const char * what)
{
  using Image = itk::Image<TPixel, 3>;
  if (array.ndim() != 3)
    throw py::value_error(std::string(what) + ": a 3D image is needed, got " + std::to_string(array.ndim()) +
                          " dimensions");
  typename Image::SizeType size;
  for (unsigned d = 0; d < 3; ++d)
    size[d] = static_cast<itk::SizeValueType>(array.shape(2 - d));
  if (size[0] * size[1] * size[2] == 0)
    throw py::value_error(std::string(what) + ": the image has no voxels");
  auto image = Image::New();
  image->SetRegions(typename Image::RegionType(size));
  SetGeometry(image.GetPointer(), geometry);
  image->GetPixelContainer()->SetImportPointer(const_cast<TPixel *>(array.data()), array.size(), false);
  return image;
}

PointSetType::Pointer
PointsFrom(const py::array_t<double, py::array::c_style | py::array::forcecast> & points, const std::string & what)
{
  if (points.ndim() != 2 || points.shape(1) != 3)
    throw py::value_error(what + ": an N x 3 array of points in mm is needed");
  auto set = PointSetType::New();
  for (py::ssize_t i = 0; i < points.shape(0); ++i)
  {
    PointSetType::PointType p;
    for (unsigned d = 0; d < 3; ++d)
      p[d] = static_cast<float>(points.at(i, d));
    set->SetPoint(static_cast<PointSetType::PointIdentifier>(i), p);
  }
  return set;
}

/** A displacement field as a (z, y, x, 3) float64 array sharing its buffer. */
py::tuple
FieldToPython(const FieldType * field)
{
  if (!field)
    throw py::value_error("no field");
  FieldType::Pointer owner(const_cast<FieldType *>(field));
  const auto         size = field->GetBufferedRegion().GetSize();
  auto *             data = reinterpret_cast<double *>(owner->GetBufferPointer());
  // The capsule holds a reference to the field for as long as the array lives.
  py::capsule keep(new FieldType::Pointer(owner), [](void * p) { delete static_cast<FieldType::Pointer *>(p); });
  py::array_t<double> array({ static_cast<py::ssize_t>(size[2]), static_cast<py::ssize_t>(size[1]),
                              static_cast<py::ssize_t>(size[0]), py::ssize_t{ 3 } },
                            data, keep);
  const Geometry g = GeometryOf(field);
  return py::make_tuple(array, g.spacing, g.origin, g.direction);
}

/** An image as (array (z, y, x), spacing, origin, direction), the array
 *  sharing the image's buffer (the capsule keeps the image alive). */
template <typename TImage>
py::tuple
ImageToPython(const TImage * image)
{
  using Pixel = typename TImage::PixelType;
  typename TImage::ConstPointer owner(image);
  const auto                    size = image->GetBufferedRegion().GetSize();
  py::capsule keep(new typename TImage::ConstPointer(owner),
                   [](void * p) { delete static_cast<typename TImage::ConstPointer *>(p); });
  py::array_t<Pixel> array({ static_cast<py::ssize_t>(size[2]), static_cast<py::ssize_t>(size[1]),
                             static_cast<py::ssize_t>(size[0]) },
                           image->GetBufferPointer(), keep);
  const Geometry g = GeometryOf(image);
  return py::make_tuple(array, g.spacing, g.origin, g.direction);
}

/** A displacement field from (array (z, y, x, 3), spacing, origin, direction), copied. */
FieldType::Pointer
FieldFromPython(const py::array_t<double, py::array::c_style | py::array::forcecast> & array, const Geometry & geometry,
                const char * what)
{
  if (array.ndim() != 4 || array.shape(3) != 3)
    throw py::value_error(std::string(what) + ": a (z, y, x, 3) array of displacements in mm is needed");
  auto                field = FieldType::New();
  FieldType::SizeType size;
  for (unsigned d = 0; d < 3; ++d)
    size[d] = static_cast<itk::SizeValueType>(array.shape(2 - d));
  field->SetRegions(FieldType::RegionType(size));
  SetGeometry(field.GetPointer(), geometry);
  field->Allocate();
  std::copy_n(array.data(), array.size(), reinterpret_cast<double *>(field->GetBufferPointer()));
  return field;
}

/** The pre-alignment's matrix (row-major) and offset: T(x) = M x + offset. */
py::tuple
LinearToPython(const itk::morea::PreAlignmentTransformType * t)
{
  std::array<double, 9> matrix{};
  std::array<double, 3> offset{};
  for (unsigned r = 0; r < 3; ++r)
  {
    offset[r] = t->GetOffset()[r];
    for (unsigned c = 0; c < 3; ++c)
      matrix[3 * r + c] = t->GetMatrix()(r, c);
  }
  return py::make_tuple(matrix, offset);
}

/** A problem's images, structures and landmarks as the package reads them. */
py::dict
ProblemToPython(const itk::morea::RegistrationProblem & problem)
{
  py::dict out;
  out["fixed"] = ImageToPython(problem.fixedImage.GetPointer());
  out["moving"] = ImageToPython(problem.movingImage.GetPointer());
  py::dict structures;
  for (const auto & s : problem.structures)
    structures[py::str(s.name)] =
      py::make_tuple(s.fixedMask ? py::object(ImageToPython(s.fixedMask.GetPointer())) : py::none(),
                     s.movingMask ? py::object(ImageToPython(s.movingMask.GetPointer())) : py::none());
  out["structures"] = structures;
  auto points = [](const auto & list) {
    std::vector<std::array<double, 3>> p;
    for (const auto & q : list)
      p.push_back({ q[0], q[1], q[2] });
    return p;
  };
  if (!problem.fixedLandmarks.empty())
    out["landmarks"] = py::make_tuple(points(problem.fixedLandmarks), points(problem.movingLandmarks));
  return out;
}

/** Runs `f`, turning ITK's and the library's errors into ValueError with the
 *  library's message. */
template <typename F>
auto
UserCall(F && f)
{
  try
  {
    return f();
  }
  catch (const itk::ExceptionObject & e)
  {
    throw py::value_error(itk::morea::UserMessage(e.GetDescription()));
  }
  catch (const morea_core::Error & e)
  {
    throw py::value_error(e.what());
  }
}

/** One registration: the filter with its inputs, kept together with the
 *  arrays its images read. */
class Registration
{
public:
  Registration()
    : m_Filter(FilterType::New())
  {}

  void
  SetImages(py::array_t<float, py::array::c_style> fixed, const Geometry & fixedGeometry,
            py::array_t<float, py::array::c_style> moving, const Geometry & movingGeometry)
  {
    m_Filter->SetFixedImage(ImageOverArray<float>(fixed, fixedGeometry, "fixed image"));
    m_Filter->SetMovingImage(ImageOverArray<float>(moving, movingGeometry, "moving image"));
    m_Keep.push_back(fixed);
    m_Keep.push_back(moving);
  }

  void
  AddStructureMasks(const std::string & name, std::optional<py::array_t<std::uint8_t, py::array::c_style>> fixed,
                    const Geometry & fixedGeometry, std::optional<py::array_t<std::uint8_t, py::array::c_style>> moving,
                    const Geometry & movingGeometry)
  {
    MaskType::Pointer f, m;
    if (fixed)
    {
      f = ImageOverArray<std::uint8_t>(*fixed, fixedGeometry, ("fixed mask of '" + name + "'").c_str());
      m_Keep.push_back(*fixed);
    }
    if (moving)
    {
      m = ImageOverArray<std::uint8_t>(*moving, movingGeometry, ("moving mask of '" + name + "'").c_str());
      m_Keep.push_back(*moving);
    }
    Call([&] { m_Filter->AddStructure(name, f, m); });
  }

  void
  AddStructurePoints(const std::string & name, std::optional<py::array> fixed, std::optional<py::array> moving)
  {
    PointSetType::Pointer f = fixed ? PointsFrom(*fixed, "fixed points of '" + name + "'") : nullptr;
    PointSetType::Pointer m = moving ? PointsFrom(*moving, "moving points of '" + name + "'") : nullptr;
    Call([&] { m_Filter->AddStructurePoints(name, f, m); });
  }

  void
  SetLandmarks(py::array fixed, py::array moving)
  {
    m_Filter->SetFixedLandmarks(PointsFrom(fixed, "fixed landmarks"));
    m_Filter->SetMovingLandmarks(PointsFrom(moving, "moving landmarks"));
  }

  void
  SetInitialTransform(const std::array<double, 9> & matrix, const std::array<double, 3> & offset)
  {
    auto affine = itk::AffineTransform<double, 3>::New();
    itk::AffineTransform<double, 3>::MatrixType m;
    itk::AffineTransform<double, 3>::OutputVectorType o;
    for (unsigned r = 0; r < 3; ++r)
    {
      o[r] = offset[r];
      for (unsigned c = 0; c < 3; ++c)
        m(r, c) = matrix[3 * r + c];
    }
    affine->SetMatrix(m);
    affine->SetOffset(o);
    m_Filter->SetInitialMovingTransform(affine);
  }

  void
  SetParameterFile(const std::string & path)
  {
    Call([&] { m_Filter->SetParameterFile(path); });
  }
  void
  SetParameter(const std::string & key, const std::string & value)
  {
    Call([&] { m_Filter->SetParameter(key, value); });
  }
  void
  SetBackend(const std::string & backend)
  {
    Call([&] { m_Filter->SetBackend(backend); });
  }
  void
  SetSelection(const std::string & selection)
  {
    Call([&] { m_Filter->SetSelection(selection); });
  }
  void
  SetCheckpoint(const std::string & path, const std::string & every, bool resume)
  {
    const auto schedule = UserCall([&] { return morea_core::CheckpointSchedule::Parse(every); }); // before any is set
    m_Filter->SetCheckpointFile(path);
    m_Filter->SetCheckpointInterval(schedule.generations);
    m_Filter->SetCheckpointSeconds(schedule.seconds);
    m_Filter->SetResume(resume);
  }

  /** Runs the registration with the GIL released. `onGeneration(generation,
   *  total, front size, best guidance)` runs after each generation; when it
   *  raises, or Ctrl-C is pressed, the run stops after the current
   *  generation and the exception (KeyboardInterrupt) is raised here. */
  void
  Run(const std::function<void(std::size_t, std::size_t, std::size_t, double)> & onGeneration)
  {
    std::atomic<bool>          aborting{ false };
    std::unique_ptr<py::error_already_set> raised;
    FilterType *               filter = m_Filter.GetPointer();
    const unsigned long        tag = m_Filter->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) {
      py::gil_scoped_acquire gil;
      try
      {
        if (PyErr_CheckSignals() != 0)
          throw py::error_already_set();
        if (onGeneration)
        {
          const auto & r = filter->GetLastGenerationRecord();
          onGeneration(r.generation, filter->GetNumberOfGenerations(), r.archiveSize, r.bestGuidance);
        }
      }
      catch (py::error_already_set & e)
      {
        raised = std::make_unique<py::error_already_set>(std::move(e));
        aborting = true;
        filter->AbortGenerateDataOn();
      }
    });
    std::string failure;
    {
      py::gil_scoped_release release;
      try
      {
        m_Filter->Update();
      }
      catch (const itk::ProcessAborted &)
      {
        if (!aborting)
          failure = "the registration was aborted";
      }
      catch (const itk::ExceptionObject & e)
      {
        failure = e.GetDescription();
      }
      catch (const std::exception & e)
      {
        failure = e.what();
      }
    }
    m_Filter->RemoveObserver(tag);
    m_Filter->AbortGenerateDataOff();
    if (raised)
      throw *raised;
    if (!failure.empty())
      throw std::runtime_error(itk::morea::UserMessage(failure));
  }

  /** The front's ids and objective values (magnitude, intensity, guidance), by ascending guidance. */
  std::pair<std::vector<std::uint64_t>, std::vector<std::array<double, 3>>>
  Front() const
  {
    std::pair<std::vector<std::uint64_t>, std::vector<std::array<double, 3>>> out;
    for (const auto & s : m_Filter->GetApproximationSet())
    {
      out.first.push_back(s.id);
      out.second.push_back(s.objectives);
    }
    return out;
  }

  std::vector<std::pair<std::string, std::size_t>>
  Selected() const
  {
    std::vector<std::pair<std::string, std::size_t>> out;
    for (itk::SizeValueType i = 0; i < m_Filter->GetNumberOfSelectedSolutions(); ++i)
      out.emplace_back(m_Filter->GetSelectedSolutionLabel(i), m_Filter->GetSelectedSolutionIndex(i));
    return out;
  }

  /** Indices into the front that a selection string names, in its order. */
  std::vector<std::pair<std::string, std::size_t>>
  Choose(const std::string & selection) const
  {
    std::vector<std::pair<std::string, std::size_t>> out;
    try
    {
      for (const auto & c : itk::morea::SelectSolutions(m_Filter->GetApproximationSet(), selection))
        out.emplace_back(c.label, c.index);
    }
    catch (const std::exception & e)
    {
      throw py::value_error(e.what());
    }
    return out;
  }

  /** Front solution `index` rasterised on the preprocessed grid: the fields
   *  fixed -> moving and moving -> fixed. The chosen solutions' are reused. */
  py::tuple
  Fields(std::size_t index) const
  {
    const auto fields = FieldsOf(index);
    return py::make_tuple(FieldToPython(fields.fixedToMoving), FieldToPython(fields.movingToFixed));
  }

  /** Solution `index` scored on the preprocessed problem (Dice, Hausdorff,
   *  landmarks, folds, inverse consistency) as JSON text. */
  std::string
  Scores(std::size_t index) const
  {
    const auto   fields = FieldsOf(index);
    const auto & problem = FinishedRun().preprocessed.problem;
    const double margin = m_Filter->GetParameters().GetReal("evaluation_border_margin");
    py::gil_scoped_release release;
    return UserCall([&] {
      return itk::morea::ScoresToJson(
               itk::morea::EvaluateRegistration(problem, fields.fixedToMoving, fields.movingToFixed, margin))
        .dump();
    });
  }

  /** Writes the run's folder as `morea register` does, with the solutions
   *  `chosen` ((label, front index) pairs) in it; returns summary.json's text. */
  std::string
  Save(const std::string & folder, const std::vector<std::pair<std::string, std::size_t>> & chosen) const
  {
    auto run = FinishedRun(); // a copy: its chosen solutions are replaced
    std::vector<itk::morea::SelectedSolution> selected;
    for (const auto & [label, index] : chosen)
    {
      if (label.empty() || label.find_first_of("/\\") != std::string::npos || label[0] == '.')
        throw py::value_error("save: '" + label + "' cannot name a solution's folder");
      itk::morea::SelectedSolution s;
      s.choice.label = label;
      s.choice.index = index;
      s.fields = FieldsOf(index);
      s.original = itk::morea::MakeOriginalFrameTransforms(s.fields, run.preprocessed.rigidTransform);
      selected.push_back(std::move(s));
    }
    run.selected = std::move(selected);
    const auto parameters = m_Filter->GetParameters();
    py::gil_scoped_release release;
    return UserCall([&] {
      const morea_core::OutputFolderLock ownership(folder);
      return itk::morea::WriteRegistrationOutputs(run, parameters, folder).dump();
    });
  }

  /** The inputs' problem preprocessed as a run would (the parameters'
   *  preprocessing keys): images, masks, landmarks, the pre-alignment and a
   *  report. */
  py::dict
  Preprocess() const
  {
    const auto problem = UserCall([&] { return m_Filter->MakeRegistrationProblem(); });
    const auto options = UserCall([&] { return itk::morea::PreprocessOptions::FromParameters(m_Filter->GetParameters()); });
    itk::morea::PreprocessResult result;
    {
      py::gil_scoped_release release;
      result = UserCall([&] { return itk::morea::Preprocess(problem, options); });
    }
    py::dict out = ProblemToPython(result.problem);
    out["pre_alignment"] = LinearToPython(result.rigidTransform);
    const auto & r = result.report;
    py::dict     report;
    report["crop_structure"] = r.cropStructure;
    report["rigid_structure"] = r.rigidStructure;
    report["spacing"] = r.spacing;
    report["size"] = std::array<std::size_t, 3>{ r.size[0], r.size[1], r.size[2] };
    report["dropped_structures"] = r.droppedStructures;
    report["dropped_reasons"] = r.droppedReasons;
    out["report"] = report;
    return out;
  }

  /** The inputs' problem scored under a registration given as fields (each
   *  (array, geometry) or None: identity / no inverse); JSON text. */
  std::string
  Evaluate(std::optional<py::array> fixedToMoving, const Geometry & fixedToMovingGeometry,
           std::optional<py::array> movingToFixed, const Geometry & movingToFixedGeometry, double borderMargin) const
  {
    const auto         problem = UserCall([&] { return m_Filter->MakeRegistrationProblem(); });
    FieldType::Pointer forward, inverse;
    if (fixedToMoving)
      forward = FieldFromPython(*fixedToMoving, fixedToMovingGeometry, "fixed_to_moving");
    if (movingToFixed)
      inverse = FieldFromPython(*movingToFixed, movingToFixedGeometry, "moving_to_fixed");
    if (borderMargin < 0.0)
      borderMargin = m_Filter->GetParameters().GetReal("evaluation_border_margin");
    py::gil_scoped_release release;
    return UserCall(
      [&] { return itk::morea::ScoresToJson(itk::morea::EvaluateRegistration(problem, forward, inverse, borderMargin)).dump(); });
  }

  /** The pre-alignment, fixed -> moving: T(x) = M x + offset. */
  py::tuple
  PreAlignment() const
  {
    return LinearToPython(m_Filter->GetRigidTransform());
  }

  std::string
  BackendUsed() const
  {
    return m_Filter->GetBackendUsed();
  }
  std::string
  BackendNote() const
  {
    return m_Filter->GetBackendNote();
  }
  std::size_t
  ResumedAtGeneration() const
  {
    return m_Filter->GetResumedAtGeneration();
  }

private:
  template <typename F>
  static void
  Call(F && f)
  {
    UserCall([&] {
      f();
      return 0;
    });
  }

  const itk::morea::MultiObjectiveRegistrationRun &
  FinishedRun() const
  {
    const auto & run = m_Filter->GetRegistrationRun();
    if (run.registration.front.empty())
      throw std::runtime_error("the registration has not run");
    return run;
  }

  void
  CheckIndex(std::size_t index) const
  {
    const auto & front = FinishedRun().registration.front;
    if (index >= front.size())
      throw py::index_error("solution " + std::to_string(index) + " of a front of " + std::to_string(front.size()));
  }

  /** Solution `index`'s fields: the chosen solutions' as rasterised, others now. */
  itk::morea::MeshFields
  FieldsOf(std::size_t index) const
  {
    CheckIndex(index);
    const auto & run = FinishedRun();
    for (const auto & s : run.selected)
      if (s.choice.index == index)
        return s.fields;
    py::gil_scoped_release release;
    return itk::morea::RasterizeSolution(run.registration.model.topology, run.registration.front[index].mesh,
                                         run.preprocessed.problem.fixedImage, run.preprocessed.problem.movingImage);
  }

  FilterType::Pointer    m_Filter;
  std::vector<py::array> m_Keep; ///< the arrays the input images read
};

/** A finished run's folder read back (itkRegistrationRunFolder.h), for the
 *  front navigator: any front solution rasterised on demand, its slices as
 *  PNG, its scores, and its export into the run's folder. Thread-safe. */
class SavedRun
{
public:
  explicit SavedRun(const std::string & folder)
  {
    py::gil_scoped_release release;
    m_Run = UserCall([&] { return itk::morea::ReadRunFolder(folder); });
    m_Baseline = std::make_shared<itk::morea::SolutionSliceViews>(m_Run.problem, nullptr);
  }

  std::string
  Folder() const
  {
    return m_Run.folder;
  }

  /** Per front solution: (id, magnitude, intensity, guidance, constraint, chosen labels). */
  std::vector<std::tuple<std::uint64_t, double, double, double, double, std::string>>
  Front() const
  {
    std::vector<std::tuple<std::uint64_t, double, double, double, double, std::string>> out;
    for (std::size_t i = 0; i < m_Run.front.size(); ++i)
    {
      const auto & f = m_Run.front[i].fitness;
      out.emplace_back(m_Run.front[i].id, f.objectives[0], f.objectives[1], f.objectives[2], f.constraint,
                       m_Run.chosen[i]);
    }
    return out;
  }

  std::string
  Summary() const
  {
    return m_Run.summary.dump();
  }

  /** Voxels along x, y, z; the structure the slices go through by default and
   *  its slices (sagittal, coronal, axial); the structures in colour order. */
  py::dict
  Layout() const
  {
    py::dict out;
    out["size"] = m_Baseline->Size();
    out["focus"] = m_Baseline->FocusStructure();
    py::dict slices;
    for (const auto axis : { itk::morea::SliceAxis::Axial, itk::morea::SliceAxis::Coronal, itk::morea::SliceAxis::Sagittal })
      slices[itk::morea::SliceAxisName(axis)] = m_Baseline->FocusSlice(axis);
    out["focus_slices"] = slices;
    out["structures"] = m_Baseline->StructureNames();
    std::vector<std::string> colors;
    for (std::size_t i = 0; i < m_Baseline->StructureNames().size(); ++i)
    {
      const auto c = itk::morea::StructureColor(i);
      char       hex[8];
      std::snprintf(hex, sizeof hex, "#%02x%02x%02x", c[0], c[1], c[2]);
      colors.emplace_back(hex);
    }
    out["colors"] = colors;
    const auto & spacing = m_Run.problem.fixedImage->GetSpacing();
    out["spacing"] = std::array<double, 3>{ { spacing[0], spacing[1], spacing[2] } };
    return out;
  }

  /** Solution `index`'s slice as PNG bytes, `width` pixels across the widest
   *  slice; index -1: before registration (identity). */
  py::bytes
  SlicePng(long index, const std::string & axis, long slice, const std::string & view, bool contours, int width)
  {
    std::string png;
    {
      py::gil_scoped_release release;
      png = UserCall([&] {
        const auto views = ViewsOf(index);
        if (width < 64 || width > 2048)
          throw morea_core::Error("the slice width must be 64 to 2048 pixels");
        return views
          ->Render(itk::morea::SliceAxisFromName(axis), slice, itk::morea::SliceViewFromName(view), contours,
                   views->PixelsPerMmForWidth(width))
          .EncodePng();
      });
    }
    return py::bytes(png);
  }

  /** Solution `index` scored on the preprocessed problem, JSON text. */
  std::string
  Scores(long index)
  {
    py::gil_scoped_release release;
    return UserCall([&] {
      const auto entry = Entry(index);
      std::lock_guard<std::mutex> lock(entry->mutex);
      if (entry->scores.empty())
      {
        nlohmann::json scores;
        if (!m_Run.problem.structures.empty() || !m_Run.problem.fixedLandmarks.empty())
          scores = itk::morea::ScoresToJson(itk::morea::EvaluateRegistration(
            m_Run.problem, entry->fields.fixedToMoving, entry->fields.movingToFixed,
            m_Run.parameters.GetReal("evaluation_border_margin")));
        const auto [jmin, jmax] = entry->views->JacobianRange();
        scores["jacobian_min"] = jmin;
        scores["jacobian_max"] = jmax;
        entry->scores = scores.dump();
      }
      return entry->scores;
    });
  }

  /** Writes solution `index` into RUN/solution_<id>/; returns that folder. */
  std::string
  Export(long index)
  {
    py::gil_scoped_release release;
    return UserCall([&] {
      const auto entry = Entry(index);
      return itk::morea::ExportSavedSolution(m_Run, static_cast<std::size_t>(index), entry->fields);
    });
  }

private:
  struct Cached
  {
    std::mutex                                           mutex; ///< guards scores
    itk::morea::MeshFields                               fields;
    std::shared_ptr<const itk::morea::SolutionSliceViews> views;
    std::string                                          scores;
  };

  std::shared_ptr<const itk::morea::SolutionSliceViews>
  ViewsOf(long index)
  {
    if (index == -1)
      return m_Baseline;
    return Entry(index)->views;
  }

  /** Solution `index` rasterised (the last few are kept). */
  std::shared_ptr<Cached>
  Entry(long index)
  {
    if (index < 0 || static_cast<std::size_t>(index) >= m_Run.front.size())
      throw morea_core::Error("solution " + std::to_string(index) + " is not in the front of " +
                           std::to_string(m_Run.front.size()));
    std::lock_guard<std::mutex> lock(m_Mutex); // one rasterisation at a time
    for (auto it = m_Cache.begin(); it != m_Cache.end(); ++it)
      if (it->first == index)
      {
        m_Cache.splice(m_Cache.begin(), m_Cache, it);
        return it->second;
      }
    auto entry = std::make_shared<Cached>();
    entry->fields = itk::morea::RasterizeSavedSolution(m_Run, static_cast<std::size_t>(index));
    entry->views = std::make_shared<itk::morea::SolutionSliceViews>(m_Run.problem, entry->fields.fixedToMoving);
    m_Cache.emplace_front(index, entry);
    if (m_Cache.size() > 6)
      m_Cache.pop_back();
    return entry;
  }

  itk::morea::SavedRegistrationRun                         m_Run;
  std::shared_ptr<const itk::morea::SolutionSliceViews>    m_Baseline;
  std::mutex                                               m_Mutex;
  std::list<std::pair<long, std::shared_ptr<Cached>>>      m_Cache;
};
} // namespace

PYBIND11_MODULE(_morea, m)
{
  m.doc() = "MOREA multi-objective deformable registration (the ITK filter behind morea.register)";
  py::class_<Geometry>(m, "Geometry")
    .def(py::init<>())
    .def(py::init([](std::array<double, 3> spacing, std::array<double, 3> origin, std::array<double, 9> direction) {
           return Geometry{ spacing, origin, direction };
         }),
         py::arg("spacing"), py::arg("origin"), py::arg("direction"))
    .def_readwrite("spacing", &Geometry::spacing)
    .def_readwrite("origin", &Geometry::origin)
    .def_readwrite("direction", &Geometry::direction);
  m.def(
    "parse_checkpoint_every",
    [](const std::string & text) {
      const auto schedule = UserCall([&] { return morea_core::CheckpointSchedule::Parse(text); });
      return std::make_pair(schedule.generations, schedule.seconds);
    },
    py::arg("text"), "(generations, seconds) of a --checkpoint-every value; ValueError when it is none");
  m.def(
    "phantom",
    [](double spacing, std::uint64_t seed) {
      morea_core::PhantomOptions options;
      options.spacing = spacing;
      options.seed = seed;
      const auto phantomCase = UserCall([&] { return morea_core::PelvisPhantom(options).Generate(); });
      const auto problem = itk::morea::MakePhantomProblem(phantomCase);
      py::dict   out = ProblemToPython(problem);
      out["true_fixed_to_moving"] = FieldToPython(itk::morea::ToDisplacementField(phantomCase.fixedToMoving));
      out["true_moving_to_fixed"] = FieldToPython(itk::morea::ToDisplacementField(phantomCase.movingToFixed));
      return out;
    },
    py::arg("spacing"), py::arg("seed"));
  m.def(
    "read_rtstruct",
    [](const std::string & path, std::array<std::size_t, 3> size, const Geometry & geometry,
       const std::vector<std::string> & names) {
      auto reference = MaskType::New();
      reference->SetRegions(MaskType::RegionType(MaskType::SizeType{ { size[0], size[1], size[2] } }));
      SetGeometry(reference.GetPointer(), geometry);
      py::dict out;
      UserCall([&] {
        const auto rois = itk::morea::ReadRTStructureSet(path);
        std::vector<const itk::morea::RTStructureROI *> wanted;
        for (const auto & name : names)
          wanted.push_back(&itk::morea::FindROI(rois, name));
        if (names.empty())
          for (const auto & roi : rois)
            wanted.push_back(&roi);
        for (const auto * roi : wanted)
        {
          auto points = itk::morea::ContourPoints(*roi);
          std::vector<std::array<double, 3>> p;
          for (const auto & q : points)
            p.push_back({ q[0], q[1], q[2] });
          out[py::str(roi->name)] =
            py::make_tuple(ImageToPython(itk::morea::RasterizeROI(*roi, reference).GetPointer()), p);
        }
        return 0;
      });
      return out;
    },
    py::arg("path"), py::arg("size"), py::arg("geometry"), py::arg("names"));
  py::class_<SavedRun>(m, "SavedRun")
    .def(py::init<const std::string &>(), py::arg("folder"))
    .def_property_readonly("folder", &SavedRun::Folder)
    .def("front", &SavedRun::Front)
    .def("summary", &SavedRun::Summary)
    .def("layout", &SavedRun::Layout)
    .def("slice_png", &SavedRun::SlicePng, py::arg("index"), py::arg("axis"), py::arg("slice"), py::arg("view"),
         py::arg("contours"), py::arg("width"))
    .def("scores", &SavedRun::Scores, py::arg("index"))
    .def("export", &SavedRun::Export, py::arg("index"));
  py::class_<Registration>(m, "Registration")
    .def(py::init<>())
    .def("set_images", &Registration::SetImages)
    .def("add_structure_masks", &Registration::AddStructureMasks)
    .def("add_structure_points", &Registration::AddStructurePoints)
    .def("set_landmarks", &Registration::SetLandmarks)
    .def("set_initial_transform", &Registration::SetInitialTransform)
    .def("set_parameter_file", &Registration::SetParameterFile)
    .def("set_parameter", &Registration::SetParameter)
    .def("set_backend", &Registration::SetBackend)
    .def("set_selection", &Registration::SetSelection)
    .def("set_checkpoint", &Registration::SetCheckpoint)
    .def("run", &Registration::Run, py::arg("on_generation") = nullptr)
    .def("front", &Registration::Front)
    .def("selected", &Registration::Selected)
    .def("choose", &Registration::Choose)
    .def("fields", &Registration::Fields)
    .def("pre_alignment", &Registration::PreAlignment)
    .def("scores", &Registration::Scores)
    .def("save", &Registration::Save)
    .def("preprocess", &Registration::Preprocess)
    .def("evaluate", &Registration::Evaluate)
    .def_property_readonly("backend_used", &Registration::BackendUsed)
    .def_property_readonly("backend_note", &Registration::BackendNote)
    .def_property_readonly("resumed_at_generation", &Registration::ResumedAtGeneration);
}
