// The Python binding (module morea._morea): one registration through
// itk::MultiObjectiveMeshRegistrationFilter on numpy arrays with their
// geometry. The package (wrapping/python/morea) turns SimpleITK, itk and
// numpy images into these arrays and the results back into transforms.
#include "itkImportImageContainer.h"
#include "itkMultiObjectiveMeshRegistrationFilter.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <map>
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
  SetCheckpoint(const std::string & path, std::size_t interval, bool resume)
  {
    m_Filter->SetCheckpointFile(path);
    m_Filter->SetCheckpointInterval(interval);
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
    const auto & run = m_Filter->GetRegistrationRun();
    if (index >= run.registration.front.size())
      throw py::index_error("solution " + std::to_string(index) + " of a front of " +
                            std::to_string(run.registration.front.size()));
    for (const auto & s : run.selected)
      if (s.choice.index == index)
        return py::make_tuple(FieldToPython(s.fields.fixedToMoving), FieldToPython(s.fields.movingToFixed));
    itk::morea::MeshFields fields;
    {
      py::gil_scoped_release release;
      fields = itk::morea::RasterizeSolution(run.registration.model.topology, run.registration.front[index].mesh,
                                             run.preprocessed.problem.fixedImage, run.preprocessed.problem.movingImage);
    }
    return py::make_tuple(FieldToPython(fields.fixedToMoving), FieldToPython(fields.movingToFixed));
  }

  /** The pre-alignment, fixed -> moving: T(x) = M x + offset. */
  py::tuple
  PreAlignment() const
  {
    const auto *          t = m_Filter->GetRigidTransform();
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
    try
    {
      f();
    }
    catch (const itk::ExceptionObject & e)
    {
      throw py::value_error(itk::morea::UserMessage(e.GetDescription()));
    }
  }

  FilterType::Pointer    m_Filter;
  std::vector<py::array> m_Keep; ///< the arrays the input images read
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
    .def_property_readonly("backend_used", &Registration::BackendUsed)
    .def_property_readonly("backend_note", &Registration::BackendNote)
    .def_property_readonly("resumed_at_generation", &Registration::ResumedAtGeneration);
}
