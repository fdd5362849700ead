/*=========================================================================
 *  MultiObjectiveRegistration: MOREA as an ITK process object.
 *=========================================================================*/
#ifndef itkMultiObjectiveMeshRegistrationFilter_h
#define itkMultiObjectiveMeshRegistrationFilter_h

#include "itkDataObjectDecorator.h"
#include "itkMultiObjectiveMeshRegistrationFilterSupport.h"
#include "itkProcessObject.h"
#include "itkSimpleDataObjectDecorator.h"
#include "morea/ParameterSet.h"

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
 * (AddStructure); optional body masks restrict the foreground. Parameters are a
 * ::morea::ParameterSet (the MOREA parameter-file keys), set whole, from a TOML
 * file, key by key or through the convenience setters.
 *
 * The run: the problem is validated and preprocessed (isotropic resampling,
 * optional rigid pre-alignment on a structure, cropping, intensity window),
 * MOREA runs on the preprocessed images, and the solutions named by the
 * selection ("best-guidance", "knee", "weighted:a:b:c", "nearest:m:i:g",
 * "all"; comma-separated) are rasterised into displacement field transforms.
 *
 * Outputs: 0 is the approximation set (ApproximationSetDecorator), 1 the rigid
 * pre-alignment, then two transforms per chosen solution i: fixed to moving
 * (output 2 + 2i) and moving to fixed (output 3 + 2i). Their number depends on
 * the selection and the set, so they exist only after Update().
 *
 * \warning The displacement field transforms live in the preprocessed frame:
 * their fields are on the preprocessed grid (GetPreprocessedFixedImage()), and
 * they relate the fixed image to the moving image *after* the rigid
 * pre-alignment. To map a fixed point x into the original moving image, apply
 * GetRigidTransform() after the fixed-to-moving transform, rigid(x + u(x));
 * e.g. a CompositeTransform with the rigid transform added first and the
 * displacement field transform second. Without pre-alignment
 * (preprocess_rigid_structure = "none") the rigid transform is the identity.
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
  using RigidTransformType = morea::RigidTransformType;
  using DisplacementFieldTransformType = morea::DisplacementFieldTransformType;
  using ParameterSetType = ::morea::ParameterSet;
  using GenerationRecordType = ::morea::GenerationRecord;
  using PreprocessReportType = morea::PreprocessReport;

  using ApproximationSolutionType = morea::ApproximationSolution;
  using ApproximationSetType = morea::ApproximationSet;
  using ApproximationSetDecorator = SimpleDataObjectDecorator<ApproximationSetType>;
  using DecoratedRigidTransformType = DataObjectDecorator<RigidTransformType>;
  using DecoratedDisplacementFieldTransformType = DataObjectDecorator<DisplacementFieldTransformType>;

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

  /** CPU threads evaluating solutions; 0 (the default): all. */
  itkSetMacro(NumberOfThreadsToUse, SizeValueType);
  itkGetConstMacro(NumberOfThreadsToUse, SizeValueType);
  /** Checkpoint file of the optimiser; empty (the default): none. */
  itkSetMacro(CheckpointFile, std::string);
  itkGetConstReferenceMacro(CheckpointFile, std::string);
  /** Write the checkpoint every this many generations (and after the last); 0: only after the last. */
  itkSetMacro(CheckpointInterval, SizeValueType);
  itkGetConstMacro(CheckpointInterval, SizeValueType);
  /** Continue from the checkpoint file when it exists. Generations restored
   *  from it fire no IterationEvent. */
  itkSetMacro(Resume, bool);
  itkGetConstMacro(Resume, bool);
  itkBooleanMacro(Resume);
  /** Which solutions get transform outputs (comma-separated): best-guidance,
   *  knee, weighted:a:b:c (weights of the normalised objectives), nearest:m:i:g
   *  (objective values), all. Default "best-guidance". */
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

  /** Chosen solution i, fixed points to moving points (preprocessed frame):
   *  the transform to resample the preprocessed moving image onto the fixed grid
   *  with. Its inverse field is set, so GetInverseTransform() works. */
  const DecoratedDisplacementFieldTransformType *
  GetFixedToMovingTransformOutput(SizeValueType i) const;
  const DisplacementFieldTransformType *
  GetFixedToMovingTransform(SizeValueType i) const;
  /** Chosen solution i, moving points to fixed points (preprocessed frame). */
  const DecoratedDisplacementFieldTransformType *
  GetMovingToFixedTransformOutput(SizeValueType i) const;
  const DisplacementFieldTransformType *
  GetMovingToFixedTransform(SizeValueType i) const;

  /** Rigid pre-alignment: preprocessed frame (fixed physical space) -> original moving image. */
  const DecoratedRigidTransformType *
  GetRigidTransformOutput() const;
  const RigidTransformType *
  GetRigidTransform() const;

  /** The preprocessed images (one isotropic grid in the fixed frame, intensities
   *  windowed to [0,1]); the transforms' fields live on this grid. */
  const InternalImageType *
  GetPreprocessedFixedImage() const
  {
    return m_PreprocessedFixedImage.GetPointer();
  }
  const InternalImageType *
  GetPreprocessedMovingImage() const
  {
    return m_PreprocessedMovingImage.GetPointer();
  }
  const PreprocessReportType &
  GetPreprocessReport() const
  {
    return m_PreprocessReport;
  }

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

  /** Output index of chosen solution i's fixed-to-moving transform; +1 for moving-to-fixed. */
  static constexpr DataObjectPointerArraySizeType FirstSolutionOutput = 2;

private:
  template <typename TImage>
  static InternalImageType::Pointer
  ToInternalImage(const TImage * image);

  void
  CheckSolutionIndex(SizeValueType i) const;

  ParameterSetType                  m_Parameters{};
  SizeValueType                     m_NumberOfThreadsToUse{ 0 };
  std::string                       m_CheckpointFile{};
  SizeValueType                     m_CheckpointInterval{ 0 };
  bool                              m_Resume{ false };
  std::string                       m_Selection{ "best-guidance" };
  std::vector<std::string>          m_StructureNames{};

  GenerationRecordType              m_LastGenerationRecord{};
  std::vector<GenerationRecordType> m_GenerationHistory{};
  SizeValueType                     m_ResumedAtGeneration{ 0 };
  std::vector<SizeValueType>        m_SelectedSolutionIndices{};
  std::vector<std::string>          m_SelectedSolutionLabels{};
  InternalImageType::Pointer         m_PreprocessedFixedImage{};
  InternalImageType::Pointer         m_PreprocessedMovingImage{};
  PreprocessReportType              m_PreprocessReport{};
};
} // namespace itk

#ifndef ITK_MANUAL_INSTANTIATION
#  include "itkMultiObjectiveMeshRegistrationFilter.hxx"
#endif

#endif
