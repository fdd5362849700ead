# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Remote-module description for an in-ITK build (ITK/Modules/Remote).
get_filename_component(MY_CURRENT_DIR "${CMAKE_CURRENT_LIST_FILE}" PATH)
file(READ "${MY_CURRENT_DIR}/README.md" DOCUMENTATION)

itk_module(MultiObjectiveRegistration
  DEPENDS
    ITKCommon
    ITKIOImageBase
    ITKIOMeta
    ITKIONIFTI
    ITKIONRRD
    ITKIOGDCM
    ITKIOPNG
    ITKIOTransformBase
    ITKIOTransformHDF5
    ITKIOTransformMatlab
    ITKImageGrid
    ITKImageIntensity
    ITKImageFunction
    ITKImageFilterBase
    ITKImageStatistics
    ITKImageLabel
    ITKLabelMap
    ITKThresholding
    ITKDistanceMap
    ITKSmoothing
    ITKBinaryMathematicalMorphology
    ITKMathematicalMorphology
    ITKConnectedComponents
    ITKTransform
    ITKDisplacementField
    ITKRegistrationMethodsv4
    ITKOptimizersv4
    ITKMetricsv4
    ITKStatistics
    ITKSpatialObjects
    ITKImageCompose
  TEST_DEPENDS
    ITKTestKernel
    ITKGoogleTest
  DESCRIPTION
    "Multi-objective deformable registration of 3D images with large deformations (MOREA): a dual-dynamic tetrahedral mesh optimised by MO-RV-GOMEA on the GPU or CPU, returning a front of fold-free registrations."
  EXCLUDE_FROM_DEFAULT
  ENABLE_SHARED
)
