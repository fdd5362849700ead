// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
/*=========================================================================
 *  MultiObjectiveRegistration: MOREA as an ITK process object.
 *=========================================================================*/
#ifndef itkMultiObjectiveMeshRegistrationFilter_h
#define itkMultiObjectiveMeshRegistrationFilter_h

#include "itkDataObjectDecorator.h"
#include "itkMultiObjectiveMeshRegistrationFilterSupport.h"
#include "itkPointSet.h"
#include "itkProcessObject.h"
#include "itkSimpleDataObjectDecorator.h"
#include "morea_core/ParameterSet.h"

#include <string>
#include <vector>

namespace itk
{
/** \class MultiObjectiveMeshRegistrationFilter
 * \brief Deformable registration of a fixed and a moving 3D image with MOREA,
 * the multi-objective dual-dynamic mesh registration method.
 *
 * MOREA optimises a tetrahedral mesh on each image with MO-RV-GOMEA for three
 * objectives at once: deformation magnitude, image dissimilarity and the
 * distance between corresponding structure contours (guidance). Instead of
 * one transform it finds an approximation set of trade-offs; this filter
 * outputs that set and the transforms of the solutions chosen from it.
 *
 * Inputs: the fixed image ("Fixed", primary) and the moving image ("Moving"),
 * both required; any 3D scalar types (cast to float internally). Structures
 * (organs, bones) are added by name with a binary mask on each image's grid
 * (AddStructure) and/or contour points on either image (AddStructurePoints,
 * itk::PointSet in physical space, e.g. RTSTRUCT contours or points picked
 * in 3D Slicer); optional body masks restrict the foreground; optional
 * landmark point sets (SetFixedLandmarks, SetMovingLandmarks) are carried
 * into the preprocessed frame for evaluation. Parameters are a
 * morea_core::ParameterSet (the MOREA parameter-file keys), set whole, from a
 * TOML file, key by key or through the convenience setters.
 *
 * The run: the problem is validated and preprocessed (isotropic resampling,
 * optional rigid pre-alignment on a structure, cropping, intensity window),
 * MOREA runs on the preprocessed images, and the solutions named by the
 * selection ("best-guidance", "knee", "weighted:a:b:c", "nearest:m:i:g",
 * "spread:N", "all"; comma-separated) are rasterised into displacement field transforms.
 *
 * Where it runs: SetBackend("auto") (the default) evaluates on the GPU's
 * texture path when a usable CUDA device is present and on the CPU
 * otherwise; "cuda" insists on the GPU (an error without one), "cuda-exact"
 * is the GPU with software interpolation for verification, "cpu" the CPU.
 * SetDevice picks the CUDA device (the cuda_gpu_id key), and
 * SetNumberOfWorkUnits the host threads (at most the multi-threader's
 * threads: all cores by default). GetBackendUsed() and
 * GetBackendNote() say where it ran and why; the log (itkDebugMacro) and
 * PrintSelf too.
 *
 * Outputs: 0 is the approximation set (ApproximationSetDecorator), 1 the rigid
 * pre-alignment, then four transforms per chosen solution i (they exist only
 * after Update(), as their number depends on the selection and the set):
 * between the original images, fixed to moving (2 + 4i) and moving to fixed
 * (3 + 4i), composites of the pre-alignment and the solution's field: what
 * ResampleImageFilter needs to map the original moving image onto the
 * original fixed grid; and in the preprocessed frame, fixed to moving
 * (4 + 4i) and moving to fixed (5 + 4i), displacement field transforms on the
 * preprocessed grid (GetPreprocessedFixedImage()) relating the images after
 * the pre-alignment.
 *
 * Events: IterationEvent after each generation (GetLastGenerationRecord()),
 * ProgressEvent; AbortGenerateData stops the run after the current generation
 * with a ProcessAborted exception.
 *
 * \ingroup MultiObjectiveRegistration
 */
template <typename TFixedImage, typename TMovingImage>
class ITK_TEMPLATE_EXPORT MultiObjectiveMeshRegistrationFilter : public ProcessObject
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(MultiObjectiveMeshRegistrationFilter);

  using Self = MultiObjectiveMeshRegistrationFilter;
  using Superclass = ProcessObject;
  using Pointer = SmartPointer<Self>;
  using ConstPointer = SmartPointer<const Self>;

  itkNewMacro(Self);
  itkTypeMacro(MultiObjectiveMeshRegistrationFilter, ProcessObject);

  static_assert(TFixedImage::ImageDimension == 3, "MOREA registers 3D images: the fixed image must be 3D");
  static_assert(TMovingImage::ImageDimension == 3, "MOREA registers 3D images: the moving image must be 3D");

  using FixedImageType = TFixedImage;
  using MovingImageType = TMovingImage;
  using InternalImageType = morea::ImageType;
  using MaskType = morea::MaskType;
  using RigidTransformType = morea::PreAlignmentTransformType;
  /** A transform given to pre-align the moving image (SetInitialMovingTransform). */
  using InitialTransformType = TransformBaseTemplate<double>;
  using DecoratedInitialTransformType = DataObjectDecorator<InitialTransformType>;
  using DisplacementFieldTransformType = morea::DisplacementFieldTransformType;
  using ParameterSetType = morea_core::ParameterSet;
  using GenerationRecordType = morea_core::GenerationRecord;
  using PreprocessReportType = morea::PreprocessReport;

  using ApproximationSolutionType = morea::ApproximationSolution;
  using ApproximationSetType = morea::ApproximationSet;
  using ApproximationSetDecorator = SimpleDataObjectDecorator<ApproximationSetType>;
  using DecoratedRigidTransformType = DataObjectDecorator<RigidTransformType>;
  using DecoratedDisplacementFieldTransformType = DataObjectDecorator<DisplacementFieldTransformType>;
  using CompositeTransformType = morea::CompositeTransformType;
  using DecoratedCompositeTransformType = DataObjectDecorator<CompositeTransformType>;
  /** Contour points and landmarks, in physical space (mm). */
  using PointSetType = PointSet<float, 3>;
  using RegistrationRunType = morea::MultiObjectiveRegistrationRun;

  using DataObjectPointerArraySizeType = ProcessObject::DataObjectPointerArraySizeType;

  // Inputs.

  virtual void
  SetFixedImage(const FixedImageType * image);
  virtual const FixedImageType *
  GetFixedImage() const;
  virtual void
  SetMovingImage(const MovingImageType * image);
  virtual const MovingImageType *
  GetMovingImage() const;

  /** Adds (or replaces) the structure `name` with a binary mask on each image's
   *  grid (0 outside). Both are needed; a missing side fails at Update(). The
   *  masks become the named inputs "FixedStructure:<name>" and "MovingStructure:<name>". */
  virtual void
  AddStructure(const std::string & name, const MaskType * fixedMask, const MaskType * movingMask);
  virtual void
  RemoveStructure(const std::string & name);
  virtual void
  RemoveAllStructures();
  const std::vector<std::string> &
  GetStructureNames() const
  {
    return m_StructureNames;
  }
  const MaskType *
  GetFixedStructureMask(const std::string & name) const;
  const MaskType *
  GetMovingStructureMask(const std::string & name) const;

  /** Adds contour points of the structure `name` on either image (null:
   *  none on that side), alone or beside its masks: each side needs a mask
   *  or points at Update(). The points become the inputs
   *  "FixedStructurePoints:<name>" and "MovingStructurePoints:<name>". */
  virtual void
  AddStructurePoints(const std::string & name, const PointSetType * fixedPoints, const PointSetType * movingPoints);
  const PointSetType *
  GetFixedStructurePoints(const std::string & name) const;
  const PointSetType *
  GetMovingStructurePoints(const std::string & name) const;

  /** Optional corresponding landmarks (the same number on both images, in
   *  the same order): carried into the preprocessed frame for evaluation. */
  itkSetInputMacro(FixedLandmarks, PointSetType);
  itkGetInputMacro(FixedLandmarks, PointSetType);
  itkSetInputMacro(MovingLandmarks, PointSetType);
  itkGetInputMacro(MovingLandmarks, PointSetType);

  /** Optional pre-alignment of the moving image, used instead of the rigid
   *  step on preprocess_rigid_structure: a linear 3D transform (rigid,
   *  similarity, affine: e.g. read from an ITK, ANTs or 3D Slicer transform
   *  file) that maps fixed points to moving points, as ResampleImageFilter
   *  uses it. Any other transform fails at Update() with a message. */
  virtual void
  SetInitialMovingTransform(const InitialTransformType * transform);
  const InitialTransformType *
  GetInitialMovingTransform() const;

  /** Optional masks of the body on each image's grid; voxels outside are background. */
  itkSetInputMacro(FixedBodyMask, MaskType);
  itkGetInputMacro(FixedBodyMask, MaskType);
  itkSetInputMacro(MovingBodyMask, MaskType);
  itkGetInputMacro(MovingBodyMask, MaskType);

  // Parameters.

  /** All MOREA parameters; keys not set keep the defaults of the paper's listing. */
  virtual void
  SetParameters(const ParameterSetType & parameters);
  const ParameterSetType &
  GetParameters() const
  {
    return m_Parameters;
  }
  /** Replaces the parameters by those of a TOML parameter file (throws ExceptionObject). */
  virtual void
  SetParameterFile(const std::string & path);
  /** Sets one key from text, as on the command line ("ea_population_size", "100"). */
  virtual void
  SetParameter(const std::string & key, const std::string & value);

  /** Convenience setters of ea_num_generations, ea_population_size and seed. */
  virtual void
  SetNumberOfGenerations(SizeValueType generations);
  SizeValueType
  GetNumberOfGenerations() const;
  virtual void
  SetPopulationSize(SizeValueType size);
  SizeValueType
  GetPopulationSize() const;
  virtual void
  SetSeed(SizeValueType seed);
  SizeValueType
  GetSeed() const;

  /** Where the solutions are evaluated: "auto" (the default: the GPU's
   *  texture path when a usable CUDA device is present, else the CPU),
   *  "cuda" (the texture path; an error without a device), "cuda-exact"
   *  (software interpolation on the GPU, for verification) or "cpu".
   *  Anything else throws. Host threads: SetNumberOfWorkUnits (at most
   *  GetMultiThreader()->GetMaximumNumberOfThreads(), all cores by default). */
  virtual void
  SetBackend(const std::string & backend);
  itkGetConstReferenceMacro(Backend, std::string);
  /** The CUDA device ordinal (the cuda_gpu_id key). */
  virtual void
  SetDevice(SizeValueType device);
  SizeValueType
  GetDevice() const;
  /** Whether candidates that a lower bound of their objectives shows refused
   *  go unsampled: "auto" (the default: where it makes runs faster), "on" or
   *  "off". The front is the same either way. */
  virtual void
  SetRefusalBounds(const std::string & choice);
  itkGetConstReferenceMacro(RefusalBounds, std::string);
  /** Checkpoint file of the optimiser; empty (the default): none. */
  itkSetMacro(CheckpointFile, std::string);
  itkGetConstReferenceMacro(CheckpointFile, std::string);
  /** Write the checkpoint every this many generations (and after the last); 0: only after the last. */
  itkSetMacro(CheckpointInterval, SizeValueType);
  itkGetConstMacro(CheckpointInterval, SizeValueType);
  /** Also write it at the first generation that ends this many seconds or
   *  more after the last checkpoint (0, the default: off). On the GPU a
   *  count of generations can mean a file a second; a duration does not. */
  itkSetClampMacro(CheckpointSeconds, double, 0.0, NumericTraits<double>::max());
  itkGetConstMacro(CheckpointSeconds, double);
  /** Continue from the checkpoint file when it exists. Generations restored
   *  from it fire no IterationEvent. */
  itkSetMacro(Resume, bool);
  itkGetConstMacro(Resume, bool);
  itkBooleanMacro(Resume);
  /** Which solutions get transform outputs (comma-separated): best-guidance,
   *  knee, weighted:a:b:c (weights of the normalised objectives), nearest:m:i:g
   *  (objective values), spread:N (N solutions spread over the front, best
   *  guidance first), all. Default "best-guidance". */
  itkSetMacro(Selection, std::string);
  itkGetConstReferenceMacro(Selection, std::string);

  // Outputs (after Update()).

  const ApproximationSetDecorator *
  GetApproximationSetOutput() const;
  /** The approximation set, by ascending guidance. */
  const ApproximationSetType &
  GetApproximationSet() const;

  SizeValueType
  GetNumberOfSelectedSolutions() const
  {
    return static_cast<SizeValueType>(m_SelectedSolutionIndices.size());
  }
  /** Index into the approximation set of chosen solution i. */
  SizeValueType
  GetSelectedSolutionIndex(SizeValueType i) const;
  /** Why solution i was chosen: "best_guidance", "knee", "weighted", "nearest", "solution_<id>". */
  const std::string &
  GetSelectedSolutionLabel(SizeValueType i) const;

  /** Chosen solution i between the original images, fixed points to moving
   *  points: the pre-alignment composed with the solution's field, the
   *  transform to resample the original moving image onto the original fixed
   *  grid with. */
  const DecoratedCompositeTransformType *
  GetFixedToMovingTransformOutput(SizeValueType i) const;
  const CompositeTransformType *
  GetFixedToMovingTransform(SizeValueType i) const;
  /** Chosen solution i between the original images, moving points to fixed points. */
  const DecoratedCompositeTransformType *
  GetMovingToFixedTransformOutput(SizeValueType i) const;
  const CompositeTransformType *
  GetMovingToFixedTransform(SizeValueType i) const;

  /** Chosen solution i in the preprocessed frame, fixed points to moving
   *  points: the transform to resample the preprocessed moving image onto the
   *  preprocessed grid with. Its inverse field is set, so
   *  GetInverseTransform() works. */
  const DecoratedDisplacementFieldTransformType *
  GetPreprocessedFixedToMovingTransformOutput(SizeValueType i) const;
  const DisplacementFieldTransformType *
  GetPreprocessedFixedToMovingTransform(SizeValueType i) const;
  /** Chosen solution i in the preprocessed frame, moving points to fixed points. */
  const DecoratedDisplacementFieldTransformType *
  GetPreprocessedMovingToFixedTransformOutput(SizeValueType i) const;
  const DisplacementFieldTransformType *
  GetPreprocessedMovingToFixedTransform(SizeValueType i) const;

  /** The pre-alignment (rigid, the initial transform given, or the identity):
   *  preprocessed frame (fixed physical space) -> original moving image. */
  const DecoratedRigidTransformType *
  GetRigidTransformOutput() const;
  const RigidTransformType *
  GetRigidTransform() const;

  /** The preprocessed images (one isotropic grid in the fixed frame, intensities
   *  windowed to [0,1]); the transforms' fields live on this grid. */
  const InternalImageType *
  GetPreprocessedFixedImage() const
  {
    return m_Run.preprocessed.problem.fixedImage.GetPointer();
  }
  const InternalImageType *
  GetPreprocessedMovingImage() const
  {
    return m_Run.preprocessed.problem.movingImage.GetPointer();
  }
  const PreprocessReportType &
  GetPreprocessReport() const
  {
    return m_Run.preprocessed.report;
  }

  /** The backend the last run evaluated on: "cpu", "cuda-texture" or
   *  "cuda-exact" ("" before a run). */
  const std::string &
  GetBackendUsed() const
  {
    return m_Run.registration.backend;
  }
  /** Why it ran there: the platform "auto" picked and why, and any faster
   *  path that could not be taken; "" when the backend asked for by name ran
   *  as asked. */
  const std::string &
  GetBackendNote() const
  {
    return m_Run.registration.backendNote;
  }
  /** Everything the last run made: the preprocessed problem, the mesh model
   *  and the front with its meshes, the chosen solutions' fields, timings
   *  (what `morea register` writes its folder from). */
  const RegistrationRunType &
  GetRegistrationRun() const
  {
    return m_Run;
  }

  /** The problem the inputs describe (images, structures, body masks,
   *  landmarks) in the original frames, as a run starts from it: for
   *  scoring or preprocessing outside a run. Throws when the inputs are
   *  incomplete (no images; unequal landmark counts). */
  morea::RegistrationProblem
  MakeRegistrationProblem() const;

  /** The latest generation's statistics (during IterationEvent: the one just run). */
  const GenerationRecordType &
  GetLastGenerationRecord() const
  {
    return m_LastGenerationRecord;
  }
  SizeValueType
  GetCurrentGeneration() const
  {
    return static_cast<SizeValueType>(m_LastGenerationRecord.generation);
  }
  /** All generations' statistics of the last run: the initial population's (generation 0),
   *  the restored ones when resumed, then one per generation run. */
  const std::vector<GenerationRecordType> &
  GetGenerationHistory() const
  {
    return m_GenerationHistory;
  }
  /** Generation the last run resumed at; 0 when it started afresh. */
  itkGetConstMacro(ResumedAtGeneration, SizeValueType);

  using Superclass::MakeOutput;
  DataObjectPointer
  MakeOutput(DataObjectPointerArraySizeType idx) override;

protected:
  MultiObjectiveMeshRegistrationFilter();
  ~MultiObjectiveMeshRegistrationFilter() override = default;

  void
  VerifyPreconditions() ITKv5_CONST override;
  void
  GenerateData() override;
  void
  PrintSelf(std::ostream & os, Indent indent) const override;

  /** Output index of chosen solution i's first transform: FirstSolutionOutput
   *  + OutputsPerSolution * i + one of the offsets below. */
  static constexpr DataObjectPointerArraySizeType FirstSolutionOutput = 2;
  static constexpr DataObjectPointerArraySizeType OutputsPerSolution = 4;
  enum SolutionOutputOffset : DataObjectPointerArraySizeType
  {
    FixedToMovingOutput = 0,
    MovingToFixedOutput = 1,
    PreprocessedFixedToMovingOutput = 2,
    PreprocessedMovingToFixedOutput = 3
  };

private:
  template <typename TImage>
  static InternalImageType::Pointer
  ToInternalImage(const TImage * image);

  void
  CheckSolutionIndex(SizeValueType i) const;
  const DataObject *
  SolutionOutputAt(SizeValueType i, SolutionOutputOffset which) const;
  /** The structures' masks and points as the problem holds them. */
  std::vector<morea::Structure>
  StructuresOfInputs() const;

  ParameterSetType                  m_Parameters{};
  std::string                       m_Backend{ "auto" };
  std::string                       m_RefusalBounds{ "auto" };
  std::string                       m_CheckpointFile{};
  SizeValueType                     m_CheckpointInterval{ 0 };
  double                            m_CheckpointSeconds{ 0.0 };
  bool                              m_Resume{ false };
  std::string                       m_Selection{ "best-guidance" };
  std::vector<std::string>          m_StructureNames{};

  GenerationRecordType              m_LastGenerationRecord{};
  std::vector<GenerationRecordType> m_GenerationHistory{};
  SizeValueType                     m_ResumedAtGeneration{ 0 };
  std::vector<SizeValueType>        m_SelectedSolutionIndices{};
  std::vector<std::string>          m_SelectedSolutionLabels{};
  RegistrationRunType               m_Run{};
};
} // namespace itk

#ifndef ITK_MANUAL_INSTANTIATION
#  include "itkMultiObjectiveMeshRegistrationFilter.hxx"
#endif

#endif
