// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: MOREA as an ITK process object.
 *
 *  Kept thin: input conversion and output wiring only; the run itself is the
 *  non-template RunMultiObjectiveRegistration (compiled once in the library).
 *=========================================================================*/
#ifndef itkMultiObjectiveMeshRegistrationFilter_hxx
#define itkMultiObjectiveMeshRegistrationFilter_hxx

#include "itkAffineTransform.h"
#include "itkCastImageFilter.h"
#include "itkMultiObjectiveMeshRegistrationFilter.h"

#include <algorithm>
#include <exception>
#include <type_traits>

namespace itk
{
namespace morea
{
namespace detail
{
inline std::string
FixedStructureInputName(const std::string & name)
{
  return "FixedStructure:" + name;
}

inline std::string
MovingStructureInputName(const std::string & name)
{
  return "MovingStructure:" + name;
}

inline std::string
FixedStructurePointsInputName(const std::string & name)
{
  return "FixedStructurePoints:" + name;
}

inline std::string
MovingStructurePointsInputName(const std::string & name)
{
  return "MovingStructurePoints:" + name;
}

/** The points of a point set as the problem holds them; null: none. */
template <typename TPointSet>
PointListType
ToPointList(const TPointSet * points)
{
  PointListType list;
  if (!points || !points->GetPoints())
    return list;
  for (auto it = points->GetPoints()->Begin(); it != points->GetPoints()->End(); ++it)
  {
    PointType p;
    for (unsigned d = 0; d < 3; ++d)
      p[d] = static_cast<double>(it.Value()[d]);
    list.push_back(p);
  }
  return list;
}
} // namespace detail
} // namespace morea

template <typename TFixedImage, typename TMovingImage>
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::MultiObjectiveMeshRegistrationFilter()
{
  Self::SetPrimaryInputName("Fixed");
  Self::AddRequiredInputName("Moving", 1);
  ProcessObject::SetNumberOfRequiredInputs(2);

  // Optional named inputs.
  Self::SetInput("FixedBodyMask", nullptr);
  Self::SetInput("MovingBodyMask", nullptr);
  Self::SetInput("FixedLandmarks", nullptr);
  Self::SetInput("InitialMovingTransform", nullptr);
  Self::SetInput("MovingLandmarks", nullptr);

  // The approximation set and the rigid transform always exist; the chosen
  // solutions' transforms are added by GenerateData.
  ProcessObject::SetNumberOfRequiredOutputs(FirstSolutionOutput);
  for (DataObjectPointerArraySizeType i = 0; i < FirstSolutionOutput; ++i)
    this->SetNthOutput(i, this->MakeOutput(i));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetFixedImage(const FixedImageType * image)
{
  if (image != this->GetFixedImage())
  {
    this->ProcessObject::SetNthInput(0, const_cast<FixedImageType *>(image));
    this->Modified();
  }
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetFixedImage() const -> const FixedImageType *
{
  return itkDynamicCastInDebugMode<const FixedImageType *>(this->ProcessObject::GetInput(0));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetMovingImage(const MovingImageType * image)
{
  if (image != this->GetMovingImage())
  {
    this->ProcessObject::SetNthInput(1, const_cast<MovingImageType *>(image));
    this->Modified();
  }
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetMovingImage() const -> const MovingImageType *
{
  return itkDynamicCastInDebugMode<const MovingImageType *>(this->ProcessObject::GetInput(1));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::AddStructure(const std::string & name,
                                                                              const MaskType *    fixedMask,
                                                                              const MaskType *    movingMask)
{
  if (name.empty())
  {
    itkExceptionMacro("AddStructure: a structure needs a name");
  }
  // Null sides are kept as null inputs, so that Update() names the structure
  // in its error rather than the call silently dropping it.
  this->ProcessObject::SetInput(morea::detail::FixedStructureInputName(name), const_cast<MaskType *>(fixedMask));
  this->ProcessObject::SetInput(morea::detail::MovingStructureInputName(name), const_cast<MaskType *>(movingMask));
  if (std::find(m_StructureNames.begin(), m_StructureNames.end(), name) == m_StructureNames.end())
    m_StructureNames.push_back(name);
  this->Modified();
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::RemoveStructure(const std::string & name)
{
  const auto it = std::find(m_StructureNames.begin(), m_StructureNames.end(), name);
  if (it == m_StructureNames.end())
    return;
  for (const auto & input :
       { morea::detail::FixedStructureInputName(name), morea::detail::MovingStructureInputName(name),
         morea::detail::FixedStructurePointsInputName(name), morea::detail::MovingStructurePointsInputName(name) })
    if (this->ProcessObject::GetInput(input))
      this->ProcessObject::RemoveInput(input);
  m_StructureNames.erase(it);
  this->Modified();
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::RemoveAllStructures()
{
  const auto names = m_StructureNames;
  for (const auto & name : names)
    this->RemoveStructure(name);
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::AddStructurePoints(const std::string &  name,
                                                                                    const PointSetType * fixedPoints,
                                                                                    const PointSetType * movingPoints)
{
  if (name.empty())
  {
    itkExceptionMacro("AddStructurePoints: a structure needs a name");
  }
  if (!fixedPoints && !movingPoints)
  {
    itkExceptionMacro("AddStructurePoints: structure '" << name << "' needs points on at least one image");
  }
  this->ProcessObject::SetInput(morea::detail::FixedStructurePointsInputName(name),
                                const_cast<PointSetType *>(fixedPoints));
  this->ProcessObject::SetInput(morea::detail::MovingStructurePointsInputName(name),
                                const_cast<PointSetType *>(movingPoints));
  if (std::find(m_StructureNames.begin(), m_StructureNames.end(), name) == m_StructureNames.end())
    m_StructureNames.push_back(name);
  this->Modified();
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetFixedStructurePoints(const std::string & name) const
  -> const PointSetType *
{
  return itkDynamicCastInDebugMode<const PointSetType *>(
    this->ProcessObject::GetInput(morea::detail::FixedStructurePointsInputName(name)));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetMovingStructurePoints(
  const std::string & name) const -> const PointSetType *
{
  return itkDynamicCastInDebugMode<const PointSetType *>(
    this->ProcessObject::GetInput(morea::detail::MovingStructurePointsInputName(name)));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetBackend(const std::string & backend)
{
  try
  {
    morea_core::ParseBackendChoice(backend);
  }
  catch (const std::exception & e)
  {
    itkExceptionMacro(<< e.what());
  }
  if (backend != m_Backend)
  {
    m_Backend = backend;
    this->Modified();
  }
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetInitialMovingTransform(
  const InitialTransformType * transform)
{
  if (transform == this->GetInitialMovingTransform())
    return;
  typename DecoratedInitialTransformType::Pointer decorated;
  if (transform)
  {
    decorated = DecoratedInitialTransformType::New();
    decorated->Set(transform);
  }
  this->ProcessObject::SetInput("InitialMovingTransform", decorated);
  this->Modified();
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetInitialMovingTransform() const
  -> const InitialTransformType *
{
  const auto * decorated =
    dynamic_cast<const DecoratedInitialTransformType *>(this->ProcessObject::GetInput("InitialMovingTransform"));
  return decorated ? decorated->Get() : nullptr;
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetRefusalBounds(const std::string & choice)
{
  try
  {
    morea_core::ParseRefusalBoundChoice(choice);
  }
  catch (const std::exception & e)
  {
    itkExceptionMacro(<< e.what());
  }
  if (choice != m_RefusalBounds)
  {
    m_RefusalBounds = choice;
    this->Modified();
  }
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetDevice(SizeValueType device)
{
  this->SetParameter("cuda_gpu_id", std::to_string(device));
}

template <typename TFixedImage, typename TMovingImage>
SizeValueType
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetDevice() const
{
  return static_cast<SizeValueType>(m_Parameters.GetInteger("cuda_gpu_id"));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetFixedStructureMask(const std::string & name) const
  -> const MaskType *
{
  return itkDynamicCastInDebugMode<const MaskType *>(
    this->ProcessObject::GetInput(morea::detail::FixedStructureInputName(name)));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetMovingStructureMask(const std::string & name) const
  -> const MaskType *
{
  return itkDynamicCastInDebugMode<const MaskType *>(
    this->ProcessObject::GetInput(morea::detail::MovingStructureInputName(name)));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetParameters(const ParameterSetType & parameters)
{
  m_Parameters = parameters;
  this->Modified();
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetParameterFile(const std::string & path)
{
  try
  {
    this->SetParameters(ParameterSetType::FromFile(path));
  }
  catch (const std::exception & e)
  {
    itkExceptionMacro(<< e.what());
  }
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetParameter(const std::string & key,
                                                                              const std::string & value)
{
  try
  {
    m_Parameters.SetFromString(key, value);
  }
  catch (const std::exception & e)
  {
    itkExceptionMacro(<< e.what());
  }
  this->Modified();
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetNumberOfGenerations(SizeValueType generations)
{
  this->SetParameter("ea_num_generations", std::to_string(generations));
}

template <typename TFixedImage, typename TMovingImage>
SizeValueType
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetNumberOfGenerations() const
{
  return static_cast<SizeValueType>(m_Parameters.GetInteger("ea_num_generations"));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetPopulationSize(SizeValueType size)
{
  this->SetParameter("ea_population_size", std::to_string(size));
}

template <typename TFixedImage, typename TMovingImage>
SizeValueType
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetPopulationSize() const
{
  return static_cast<SizeValueType>(m_Parameters.GetInteger("ea_population_size"));
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SetSeed(SizeValueType seed)
{
  this->SetParameter("seed", std::to_string(seed));
}

template <typename TFixedImage, typename TMovingImage>
SizeValueType
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetSeed() const
{
  return static_cast<SizeValueType>(m_Parameters.GetInteger("seed"));
}

template <typename TFixedImage, typename TMovingImage>
ProcessObject::DataObjectPointer
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::MakeOutput(DataObjectPointerArraySizeType idx)
{
  if (idx == 0)
  {
    return ApproximationSetDecorator::New().GetPointer();
  }
  if (idx == 1)
  {
    auto rigid = morea::RigidTransformType::New();
    rigid->SetIdentity();
    auto decorator = DecoratedRigidTransformType::New();
    decorator->Set(rigid);
    return decorator.GetPointer();
  }
  if ((idx - FirstSolutionOutput) % OutputsPerSolution < PreprocessedFixedToMovingOutput)
    return DecoratedCompositeTransformType::New().GetPointer();
  return DecoratedDisplacementFieldTransformType::New().GetPointer();
}

template <typename TFixedImage, typename TMovingImage>
std::vector<morea::Structure>
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::StructuresOfInputs() const
{
  std::vector<morea::Structure> structures;
  for (const auto & name : m_StructureNames)
  {
    morea::Structure structure;
    structure.name = name;
    structure.fixedMask = const_cast<MaskType *>(this->GetFixedStructureMask(name));
    structure.movingMask = const_cast<MaskType *>(this->GetMovingStructureMask(name));
    const PointSetType * fixedPoints = this->GetFixedStructurePoints(name);
    const PointSetType * movingPoints = this->GetMovingStructurePoints(name);
    // A point set given but empty is a mistake, not "no points".
    for (const auto & [points, side] : { std::make_pair(fixedPoints, "fixed"), std::make_pair(movingPoints, "moving") })
      if (points && points->GetNumberOfPoints() == 0)
      {
        itkExceptionMacro("structure '" << name << "': the " << side << " point set is empty");
      }
    structure.fixedPoints = morea::detail::ToPointList(fixedPoints);
    structure.movingPoints = morea::detail::ToPointList(movingPoints);
    structures.push_back(std::move(structure));
  }
  return structures;
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::VerifyPreconditions() ITKv5_CONST
{
  Superclass::VerifyPreconditions();
  // A bad selection would otherwise only show after the whole run.
  try
  {
    morea::CheckSolutionSelection(m_Selection);
  }
  catch (const std::exception & e)
  {
    itkExceptionMacro(<< e.what());
  }
}

template <typename TFixedImage, typename TMovingImage>
template <typename TImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::ToInternalImage(const TImage * image)
  -> InternalImageType::Pointer
{
  if constexpr (std::is_same_v<TImage, InternalImageType>)
  {
    // The problem only reads its images: share the input rather than copy it.
    return const_cast<InternalImageType *>(image);
  }
  else
  {
    // Not in place: that would hand the caller's buffer to the output.
    using CastFilterType = CastImageFilter<TImage, InternalImageType>;
    auto cast = CastFilterType::New();
    cast->SetInput(image);
    cast->InPlaceOff();
    cast->Update();
    InternalImageType::Pointer output = cast->GetOutput();
    output->DisconnectPipeline();
    return output;
  }
}

template <typename TFixedImage, typename TMovingImage>
morea::RegistrationProblem
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::MakeRegistrationProblem() const
{
  if (!this->GetFixedImage() || !this->GetMovingImage())
  {
    itkExceptionMacro("the fixed and the moving image are both needed");
  }
  morea::RegistrationProblem problem;
  problem.fixedImage = ToInternalImage(this->GetFixedImage());
  problem.movingImage = ToInternalImage(this->GetMovingImage());
  problem.structures = this->StructuresOfInputs();
  problem.fixedBodyMask = const_cast<MaskType *>(this->GetFixedBodyMask());
  problem.movingBodyMask = const_cast<MaskType *>(this->GetMovingBodyMask());
  problem.fixedLandmarks = morea::detail::ToPointList(this->GetFixedLandmarks());
  problem.movingLandmarks = morea::detail::ToPointList(this->GetMovingLandmarks());
  if (problem.fixedLandmarks.size() != problem.movingLandmarks.size())
  {
    itkExceptionMacro("landmarks: " << problem.fixedLandmarks.size() << " fixed and "
                                    << problem.movingLandmarks.size()
                                    << " moving points; both sets need the same points in the same order");
  }
  return problem;
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GenerateData()
{
  // Results of an earlier run must not survive a failed one.
  m_LastGenerationRecord = {};
  m_GenerationHistory.clear();
  m_ResumedAtGeneration = 0;
  m_SelectedSolutionIndices.clear();
  m_SelectedSolutionLabels.clear();
  m_Run = {};
  static_cast<ApproximationSetDecorator *>(this->ProcessObject::GetOutput(0))->Set(ApproximationSetType{});
  this->SetNumberOfIndexedOutputs(FirstSolutionOutput);
  this->UpdateProgress(0.0f);

  morea::MultiObjectiveRegistrationRun run;
  try
  {
    const morea::RegistrationProblem problem = this->MakeRegistrationProblem();

    morea::MeshRegistrationOptions options;
    options.checkpointPath = m_CheckpointFile;
    options.checkpointInterval = m_CheckpointInterval;
    options.checkpointSeconds = m_CheckpointSeconds;
    options.resume = m_Resume;
    // Host threads: the work units, but no more than the threader's threads
    // (ITK's default work units are 4 per thread; the optimiser's pool wants
    // one thread per core).
    options.threads = std::max<SizeValueType>(
      1, std::min<SizeValueType>(this->GetNumberOfWorkUnits(), this->GetMultiThreader()->GetMaximumNumberOfThreads()));
    options.backend = morea_core::ParseBackendChoice(m_Backend);
    options.refusalBounds = morea_core::ParseRefusalBoundChoice(m_RefusalBounds);
    // Between generations is the only point the run can stop at cleanly; both
    // callbacks check, so that an observer of either event stops it at once.
    const auto stopIfAborted = [this]() {
      if (this->GetAbortGenerateData())
      {
        ProcessAborted aborted(__FILE__, __LINE__);
        aborted.SetDescription("MultiObjectiveMeshRegistrationFilter: aborted after generation " +
                               std::to_string(m_LastGenerationRecord.generation));
        throw aborted;
      }
    };
    options.onGeneration = [this, stopIfAborted](const GenerationRecordType & record, std::size_t) {
      m_LastGenerationRecord = record;
      this->InvokeEvent(IterationEvent());
      stopIfAborted();
    };
    const auto progress = [this, stopIfAborted](double fraction) {
      this->UpdateProgress(static_cast<float>(fraction));
      stopIfAborted();
    };
    const morea::PreAlignmentTransformType * initial = nullptr;
    morea::PreAlignmentTransformType::Pointer convertedInitial;
    if (const InitialTransformType * given = this->GetInitialMovingTransform())
    {
      if (given->GetInputSpaceDimension() != 3 || given->GetOutputSpaceDimension() != 3)
      {
        itkExceptionMacro("initial moving transform: " << given->GetNameOfClass() << " maps "
                                                       << given->GetInputSpaceDimension() << "-D points to "
                                                       << given->GetOutputSpaceDimension()
                                                       << "-D points; a 3-D transform is needed");
      }
      initial = dynamic_cast<const morea::PreAlignmentTransformType *>(given);
      if (!initial)
      {
        // Other linear transforms (a translation, say) as the affine map they are.
        const auto * linear = dynamic_cast<const Transform<double, 3, 3> *>(given);
        if (!linear || linear->GetTransformCategory() != Transform<double, 3, 3>::TransformCategoryEnum::Linear)
        {
          itkExceptionMacro("initial moving transform: " << given->GetNameOfClass()
                                                         << " is not linear; give a translation, rigid, similarity "
                                                            "or affine transform");
        }
        typename Transform<double, 3, 3>::InputPointType origin;
        origin.Fill(0.0);
        typename Transform<double, 3, 3>::JacobianPositionType jacobian;
        linear->ComputeJacobianWithRespectToPosition(origin, jacobian);
        auto                             affine = AffineTransform<double, 3>::New();
        AffineTransform<double, 3>::MatrixType matrix;
        for (unsigned r = 0; r < 3; ++r)
          for (unsigned c = 0; c < 3; ++c)
            matrix(r, c) = jacobian(r, c);
        affine->SetMatrix(matrix);
        affine->SetOffset(linear->TransformPoint(origin) - origin);
        convertedInitial = affine;
        initial = affine;
      }
    }
    run = morea::RunMultiObjectiveRegistration(problem, m_Parameters, options, m_Selection, progress, initial);
  }
  catch (const ExceptionObject &)
  {
    throw;
  }
  catch (const std::exception & e)
  {
    // Core errors (morea_core::Error) carry a message meant for the user.
    itkExceptionMacro(<< e.what());
  }

  m_GenerationHistory = run.registration.history;
  if (!m_GenerationHistory.empty())
    m_LastGenerationRecord = m_GenerationHistory.back();
  m_ResumedAtGeneration = static_cast<SizeValueType>(run.registration.resumedAtGeneration);
  static_cast<ApproximationSetDecorator *>(this->ProcessObject::GetOutput(0))->Set(run.approximationSet);
  static_cast<DecoratedRigidTransformType *>(this->ProcessObject::GetOutput(1))->Set(run.preprocessed.rigidTransform);

  this->SetNumberOfIndexedOutputs(FirstSolutionOutput + OutputsPerSolution * run.selected.size());
  for (std::size_t i = 0; i < run.selected.size(); ++i)
  {
    const auto & selected = run.selected[i];
    m_SelectedSolutionIndices.push_back(static_cast<SizeValueType>(selected.choice.index));
    m_SelectedSolutionLabels.push_back(selected.choice.label);
    const DataObjectPointerArraySizeType first = FirstSolutionOutput + OutputsPerSolution * i;
    for (DataObjectPointerArraySizeType o = first; o < first + OutputsPerSolution; ++o)
      if (this->ProcessObject::GetOutput(o) == nullptr)
        this->SetNthOutput(o, this->MakeOutput(o));
    const auto composite = [&](DataObjectPointerArraySizeType o) {
      return static_cast<DecoratedCompositeTransformType *>(this->ProcessObject::GetOutput(first + o));
    };
    const auto field = [&](DataObjectPointerArraySizeType o) {
      return static_cast<DecoratedDisplacementFieldTransformType *>(this->ProcessObject::GetOutput(first + o));
    };
    composite(FixedToMovingOutput)->Set(selected.original.fixedToMoving);
    composite(MovingToFixedOutput)->Set(selected.original.movingToFixed);
    field(PreprocessedFixedToMovingOutput)->Set(selected.fields.fixedToMovingTransform);
    field(PreprocessedMovingToFixedOutput)->Set(selected.fields.movingToFixedTransform);
  }
  m_Run = std::move(run);
  itkDebugMacro("evaluated on the " << m_Run.registration.backend << " backend"
                                    << (m_Run.registration.backendNote.empty() ? "" : ": ")
                                    << m_Run.registration.backendNote);
  // A faster path the backend could not take is said, never dropped.
  if (!m_Run.registration.pathNote.empty())
  {
    itkWarningMacro("backend: " << m_Run.registration.pathNote);
  }
  this->UpdateProgress(1.0f);
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetApproximationSetOutput() const
  -> const ApproximationSetDecorator *
{
  return static_cast<const ApproximationSetDecorator *>(this->ProcessObject::GetOutput(0));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetApproximationSet() const
  -> const ApproximationSetType &
{
  return this->GetApproximationSetOutput()->Get();
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::CheckSolutionIndex(SizeValueType i) const
{
  if (i >= m_SelectedSolutionIndices.size())
  {
    itkExceptionMacro("chosen solution " << i << " requested, but " << m_SelectedSolutionIndices.size()
                                         << " were chosen (selection '" << m_Selection
                                         << "'; outputs exist after Update())");
  }
}

template <typename TFixedImage, typename TMovingImage>
SizeValueType
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetSelectedSolutionIndex(SizeValueType i) const
{
  this->CheckSolutionIndex(i);
  return m_SelectedSolutionIndices[i];
}

template <typename TFixedImage, typename TMovingImage>
const std::string &
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetSelectedSolutionLabel(SizeValueType i) const
{
  this->CheckSolutionIndex(i);
  return m_SelectedSolutionLabels[i];
}

template <typename TFixedImage, typename TMovingImage>
const DataObject *
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::SolutionOutputAt(SizeValueType i,
                                                                                SolutionOutputOffset which) const
{
  this->CheckSolutionIndex(i);
  return this->ProcessObject::GetOutput(FirstSolutionOutput + OutputsPerSolution * i + which);
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetFixedToMovingTransformOutput(
  SizeValueType i) const -> const DecoratedCompositeTransformType *
{
  return static_cast<const DecoratedCompositeTransformType *>(this->SolutionOutputAt(i, FixedToMovingOutput));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetFixedToMovingTransform(SizeValueType i) const
  -> const CompositeTransformType *
{
  return this->GetFixedToMovingTransformOutput(i)->Get();
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetMovingToFixedTransformOutput(
  SizeValueType i) const -> const DecoratedCompositeTransformType *
{
  return static_cast<const DecoratedCompositeTransformType *>(this->SolutionOutputAt(i, MovingToFixedOutput));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetMovingToFixedTransform(SizeValueType i) const
  -> const CompositeTransformType *
{
  return this->GetMovingToFixedTransformOutput(i)->Get();
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetPreprocessedFixedToMovingTransformOutput(
  SizeValueType i) const -> const DecoratedDisplacementFieldTransformType *
{
  return static_cast<const DecoratedDisplacementFieldTransformType *>(
    this->SolutionOutputAt(i, PreprocessedFixedToMovingOutput));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetPreprocessedFixedToMovingTransform(
  SizeValueType i) const -> const DisplacementFieldTransformType *
{
  return this->GetPreprocessedFixedToMovingTransformOutput(i)->Get();
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetPreprocessedMovingToFixedTransformOutput(
  SizeValueType i) const -> const DecoratedDisplacementFieldTransformType *
{
  return static_cast<const DecoratedDisplacementFieldTransformType *>(
    this->SolutionOutputAt(i, PreprocessedMovingToFixedOutput));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetPreprocessedMovingToFixedTransform(
  SizeValueType i) const -> const DisplacementFieldTransformType *
{
  return this->GetPreprocessedMovingToFixedTransformOutput(i)->Get();
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetRigidTransformOutput() const
  -> const DecoratedRigidTransformType *
{
  return static_cast<const DecoratedRigidTransformType *>(this->ProcessObject::GetOutput(1));
}

template <typename TFixedImage, typename TMovingImage>
auto
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::GetRigidTransform() const
  -> const RigidTransformType *
{
  return this->GetRigidTransformOutput()->Get();
}

template <typename TFixedImage, typename TMovingImage>
void
MultiObjectiveMeshRegistrationFilter<TFixedImage, TMovingImage>::PrintSelf(std::ostream & os, Indent indent) const
{
  Superclass::PrintSelf(os, indent);
  os << indent << "Structures: ";
  for (std::size_t i = 0; i < m_StructureNames.size(); ++i)
    os << (i ? ", " : "") << m_StructureNames[i];
  os << std::endl;
  os << indent << "Selection: " << m_Selection << std::endl;
  os << indent << "Backend: " << m_Backend << std::endl;
  os << indent << "BackendUsed: " << (this->GetBackendUsed().empty() ? "(none yet)" : this->GetBackendUsed())
     << std::endl;
  os << indent << "BackendNote: " << this->GetBackendNote() << std::endl;
  os << indent << "CheckpointFile: " << m_CheckpointFile << std::endl;
  os << indent << "CheckpointInterval: " << m_CheckpointInterval << std::endl;
  os << indent << "CheckpointSeconds: " << m_CheckpointSeconds << std::endl;
  os << indent << "Resume: " << (m_Resume ? "On" : "Off") << std::endl;
  os << indent << "Parameters (the main keys and those set):" << std::endl;
  morea::PrintParameters(os, m_Parameters, indent.GetNextIndent());
  os << indent << "CurrentGeneration: " << this->GetCurrentGeneration() << std::endl;
  os << indent << "ResumedAtGeneration: " << m_ResumedAtGeneration << std::endl;
  const auto * set = this->GetApproximationSetOutput();
  os << indent << "ApproximationSetSize: " << (set ? set->Get().size() : 0) << std::endl;
  os << indent << "SelectedSolutions:";
  for (std::size_t i = 0; i < m_SelectedSolutionIndices.size(); ++i)
    os << " " << m_SelectedSolutionLabels[i] << "=" << m_SelectedSolutionIndices[i];
  os << std::endl;
  os << indent << "PreprocessedGrid: ";
  if (const auto * grid = this->GetPreprocessedFixedImage())
    os << grid->GetLargestPossibleRegion().GetSize() << " voxels of " << grid->GetSpacing()[0] << " mm" << std::endl;
  else
    os << "(none)" << std::endl;
}
} // namespace itk

#endif
