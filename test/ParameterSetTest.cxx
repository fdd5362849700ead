// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
// Tests of morea_core::ParameterSet (the TOML parameter reader) and morea_core::RandomGenerator.
// Core tests: no ITK headers here.
#include "morea_core/Error.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace
{
using morea_core::Error;
using morea_core::ParameterSet;
using morea_core::ParameterSpec;

// The MOREA paper's parameter file (appendix A, listing "Parameter file used as
// basis for the main MOREA experiments"), verbatim.
const char * const kPaperListing = R"(sweep_descriptor = "$experiment_descriptor"
num_runs = 5
problem_id = "$problem_id"
zip = true

problem_guidance_enabled = true
problem_guidance_selection = "-1"

cuda_compute_level = 80
cuda_gpu_id = 0

ea_num_generations = 500
ea_population_size = 700
ea_num_clusters = 10
ea_archive_size = 2000

ea_adaptive_steering_enabled = true
ea_adaptive_steering_activated_at_num_generations = 100
ea_adaptive_steering_guidance_threshold = 1.5

morea_init_noise_method = "global-gaussian"
morea_init_noise_factor = 1.0

morea_mesh_generation_method = "annotation-group-random-bladder-10"
morea_mesh_num_points = 600
morea_max_num_mesh_levels = 1
morea_num_generations_per_level = 0

morea_magnitude_metric = "biomechanical"
morea_image_metric = "squared-differences"
morea_guidance_metric = "continuous-per-group"
morea_sampling_rate = 1.0

morea_fos_type = "edges"
morea_symmetry_mode = "transform-both"
morea_dual_dynamic_mode = "dual"
morea_repair_method = "gaussian"
morea_ams_strategy = "none"
morea_num_disruption_kernels = 0
morea_disruption_frequency = 0
)";

/** The message of the morea_core::Error thrown by `f`; fails the test when none is thrown. */
template <typename F>
std::string
ErrorMessage(F && f)
{
  try
  {
    f();
  }
  catch (const Error & e)
  {
    return e.what();
  }
  catch (const std::exception & e)
  {
    ADD_FAILURE() << "expected morea_core::Error, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected morea_core::Error, nothing was thrown";
  return "";
}

#define EXPECT_CONTAINS(haystack, needle)                                                                   \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos)                                         \
    << "message '" << (haystack) << "' does not contain '" << (needle) << "'"

bool
SameValues(const ParameterSet & a, const ParameterSet & b, std::string & firstDifference)
{
  for (const auto & spec : ParameterSet::Specs())
  {
    bool same = false;
    switch (spec.type)
    {
      case ParameterSpec::Type::Bool:
        same = a.GetBool(spec.key) == b.GetBool(spec.key);
        break;
      case ParameterSpec::Type::Integer:
        same = a.GetInteger(spec.key) == b.GetInteger(spec.key);
        break;
      case ParameterSpec::Type::Real:
        same = a.GetReal(spec.key) == b.GetReal(spec.key) ||
               (std::isnan(a.GetReal(spec.key)) && std::isnan(b.GetReal(spec.key)));
        break;
      case ParameterSpec::Type::String:
        same = a.GetString(spec.key) == b.GetString(spec.key);
        break;
    }
    if (!same)
    {
      firstDifference = spec.key;
      return false;
    }
  }
  return true;
}

std::filesystem::path
ScratchDir()
{
  const auto dir = std::filesystem::temp_directory_path() / "morea-ParameterSetTest";
  std::filesystem::create_directories(dir);
  return dir;
}
} // namespace

// ---------------------------------------------------------------------------
// Specs and defaults
// ---------------------------------------------------------------------------

TEST(ParameterSet, SpecsAreUniqueAndDefaultsSatisfyTheirOwnConstraints)
{
  std::set<std::string> keys;
  for (const auto & spec : ParameterSet::Specs())
  {
    EXPECT_TRUE(keys.insert(spec.key).second) << "duplicate key " << spec.key;
    switch (spec.type)
    {
      case ParameterSpec::Type::Bool:
        EXPECT_TRUE(std::holds_alternative<bool>(spec.defaultValue)) << spec.key;
        break;
      case ParameterSpec::Type::Integer:
        ASSERT_TRUE(std::holds_alternative<std::int64_t>(spec.defaultValue)) << spec.key;
        EXPECT_GE(static_cast<double>(std::get<std::int64_t>(spec.defaultValue)), spec.minimum) << spec.key;
        EXPECT_LE(static_cast<double>(std::get<std::int64_t>(spec.defaultValue)), spec.maximum) << spec.key;
        break;
      case ParameterSpec::Type::Real:
        ASSERT_TRUE(std::holds_alternative<double>(spec.defaultValue)) << spec.key;
        EXPECT_GE(std::get<double>(spec.defaultValue), spec.minimum) << spec.key;
        EXPECT_LE(std::get<double>(spec.defaultValue), spec.maximum) << spec.key;
        break;
      case ParameterSpec::Type::String:
      {
        ASSERT_TRUE(std::holds_alternative<std::string>(spec.defaultValue)) << spec.key;
        const auto & value = std::get<std::string>(spec.defaultValue);
        if (!spec.choices.empty())
        {
          EXPECT_NE(std::find(spec.choices.begin(), spec.choices.end(), value), spec.choices.end()) << spec.key;
        }
        break;
      }
    }
    EXPECT_EQ(&ParameterSet::Spec(spec.key), &spec);
  }
  // Every key of the paper listing is known.
  for (const char * key : { "sweep_descriptor", "num_runs", "problem_id", "zip", "problem_guidance_enabled",
                            "cuda_compute_level", "ea_archive_size", "morea_ams_strategy",
                            "morea_disruption_frequency" })
  {
    EXPECT_EQ(keys.count(key), 1u) << key;
  }
}

TEST(ParameterSet, DefaultsAreThePaperValues)
{
  const ParameterSet p;
  EXPECT_EQ(p.GetInteger("ea_num_generations"), 500);
  EXPECT_EQ(p.GetInteger("ea_population_size"), 700);
  EXPECT_EQ(p.GetInteger("ea_num_clusters"), 10);
  EXPECT_EQ(p.GetInteger("ea_archive_size"), 2000);
  EXPECT_EQ(p.GetInteger("morea_mesh_num_points"), 600);
  EXPECT_EQ(p.GetInteger("ea_adaptive_steering_activated_at_num_generations"), 100);
  EXPECT_DOUBLE_EQ(p.GetReal("ea_adaptive_steering_guidance_threshold"), 1.5);
  EXPECT_TRUE(p.GetBool("ea_adaptive_steering_enabled"));
  EXPECT_TRUE(p.GetBool("problem_guidance_enabled"));
  EXPECT_EQ(p.GetString("morea_magnitude_metric"), "biomechanical");
  EXPECT_EQ(p.GetString("morea_mesh_generation_method"), "annotation-group-random-bladder-10");
  EXPECT_EQ(p.GetString("problem_guidance_selection"), "-1");
  EXPECT_DOUBLE_EQ(p.GetReal("preprocess_isotropic_spacing"), 1.5);
  EXPECT_FALSE(p.IsExplicit("ea_population_size"));
}

TEST(ParameterSet, GettersRejectUnknownKeysAndWrongTypes)
{
  const ParameterSet p;
  EXPECT_CONTAINS(ErrorMessage([&] { p.GetInteger("no_such_key"); }), "unknown parameter 'no_such_key'");
  EXPECT_THROW(p.GetReal("no_such_key"), Error);
  EXPECT_THROW(p.GetString("no_such_key"), Error);
  EXPECT_THROW(p.GetBool("no_such_key"), Error);
  // Asking an integer key for a boolean is a programming error; it must not return garbage.
  EXPECT_THROW(p.GetBool("num_runs"), std::exception);
  EXPECT_THROW(p.GetString("ea_population_size"), std::exception);
}

// ---------------------------------------------------------------------------
// The paper's parameter file
// ---------------------------------------------------------------------------

TEST(ParameterSet, ParsesThePaperListingWithVariables)
{
  const auto p = ParameterSet::FromToml(kPaperListing,
                                        { { "experiment_descriptor", "gecco-main" }, { "problem_id", "patient-3" } },
                                        "paper.toml");
  EXPECT_EQ(p.GetString("sweep_descriptor"), "gecco-main");
  EXPECT_EQ(p.GetString("problem_id"), "patient-3");
  EXPECT_EQ(p.GetInteger("num_runs"), 5);
  EXPECT_TRUE(p.GetBool("zip"));
  EXPECT_EQ(p.GetInteger("cuda_compute_level"), 80);
  EXPECT_EQ(p.GetInteger("cuda_gpu_id"), 0);
  EXPECT_EQ(p.GetInteger("ea_population_size"), 700);
  EXPECT_EQ(p.GetInteger("ea_archive_size"), 2000);
  EXPECT_DOUBLE_EQ(p.GetReal("ea_adaptive_steering_guidance_threshold"), 1.5);
  EXPECT_DOUBLE_EQ(p.GetReal("morea_init_noise_factor"), 1.0);
  EXPECT_DOUBLE_EQ(p.GetReal("morea_sampling_rate"), 1.0);
  EXPECT_EQ(p.GetString("morea_init_noise_method"), "global-gaussian");
  EXPECT_EQ(p.GetString("morea_guidance_metric"), "continuous-per-group");
  EXPECT_EQ(p.GetString("morea_repair_method"), "gaussian");
  EXPECT_EQ(p.GetInteger("morea_disruption_frequency"), 0);
  // Keys of the listing are explicit; the module's extra keys keep their defaults.
  EXPECT_TRUE(p.IsExplicit("num_runs"));
  EXPECT_TRUE(p.IsExplicit("sweep_descriptor"));
  EXPECT_FALSE(p.IsExplicit("preprocess_isotropic_spacing"));
  EXPECT_DOUBLE_EQ(p.GetReal("preprocess_isotropic_spacing"), 1.5);
}

TEST(ParameterSet, PaperListingWithoutVariablesNamesTheMissingPlaceholder)
{
  const std::string noVariables = ErrorMessage([] { ParameterSet::FromToml(kPaperListing, {}, "paper.toml"); });
  EXPECT_CONTAINS(noVariables, "$experiment_descriptor");
  EXPECT_CONTAINS(noVariables, "paper.toml line 1");

  const std::string oneVariable =
    ErrorMessage([] { ParameterSet::FromToml(kPaperListing, { { "experiment_descriptor", "x" } }, "paper.toml"); });
  EXPECT_CONTAINS(oneVariable, "$problem_id");
  EXPECT_CONTAINS(oneVariable, "paper.toml line 3");
  EXPECT_EQ(oneVariable.find("$experiment_descriptor"), std::string::npos) << oneVariable;
}

TEST(ParameterSet, FromFileReadsTheListingAndNamesThePathInErrors)
{
  const auto path = (ScratchDir() / "paper.toml").string();
  {
    std::ofstream out(path, std::ios::binary);
    out << kPaperListing;
  }
  const auto p = ParameterSet::FromFile(path, { { "experiment_descriptor", "e" }, { "problem_id", "p" } });
  EXPECT_EQ(p.GetString("problem_id"), "p");
  EXPECT_EQ(p.GetInteger("cuda_compute_level"), 80);

  EXPECT_CONTAINS(ErrorMessage([&] { ParameterSet::FromFile(path); }), path + " line 1");
  const auto missing = (ScratchDir() / "does-not-exist.toml").string();
  EXPECT_CONTAINS(ErrorMessage([&] { ParameterSet::FromFile(missing); }), missing);
}

// ---------------------------------------------------------------------------
// Placeholders
// ---------------------------------------------------------------------------

TEST(ParameterSet, PlaceholdersAreSubstitutedInsideStringsButNotInComments)
{
  const std::string text = "# this comment mentions $undefined and is ignored\n"
                           "sweep_descriptor = \"run#$name-$n\" # trailing comment with $undefined too\n"
                           "num_runs = $n\n";
  const auto p = ParameterSet::FromToml(text, { { "name", "abc" }, { "n", "7" } });
  EXPECT_EQ(p.GetString("sweep_descriptor"), "run#abc-7");
  EXPECT_EQ(p.GetInteger("num_runs"), 7);

  // An escaped quote does not end the string: the '#' after it is not a comment.
  const auto q = ParameterSet::FromToml("problem_id = \"a\\\"#$v\"\n", { { "v", "w" } });
  EXPECT_EQ(q.GetString("problem_id"), "a\"#w");
}

TEST(ParameterSet, PlaceholderInCommentAfterStringEndingInBackslashIsIgnored)
{
  // "C:\\" ends with an escaped backslash; the quote after it closes the string,
  // so the rest of the line is a comment and its placeholder must be ignored.
  const auto p = ParameterSet::FromToml("problem_id = \"C:\\\\\" # uses $HOME\n", {});
  EXPECT_EQ(p.GetString("problem_id"), "C:\\");
}

TEST(ParameterSet, PlaceholdersInLiteralStrings)
{
  // A '#' inside a 'literal string' is not a comment; a '"' inside one does not open a string.
  const auto p = ParameterSet::FromToml("problem_id = 'a#$v'\nsweep_descriptor = 'say \"hi' # $ignored\n",
                                        { { "v", "w" } });
  EXPECT_EQ(p.GetString("problem_id"), "a#w");
  EXPECT_EQ(p.GetString("sweep_descriptor"), "say \"hi");
}

TEST(ParameterSet, SubstitutePlaceholdersReportsLineAndKeepsText)
{
  EXPECT_EQ(morea_core::SubstitutePlaceholders("a = \"$x$y\"\nb = 1 # $z\n", { { "x", "1" }, { "y", "2" } }, "s"),
            "a = \"12\"\nb = 1 # $z\n");
  // A lone '$' (no name) is kept as is.
  EXPECT_EQ(morea_core::SubstitutePlaceholders("a = \"5 $\"\n", {}, "s"), "a = \"5 $\"\n");
  const std::string message =
    ErrorMessage([] { morea_core::SubstitutePlaceholders("a = 1\n\nb = \"$missing_var\"\n", {}, "src"); });
  EXPECT_CONTAINS(message, "src line 3");
  EXPECT_CONTAINS(message, "'$missing_var'");
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

TEST(ParameterSet, UnknownKeyIsAnErrorWithLineAndSuggestion)
{
  const std::string message =
    ErrorMessage([] { ParameterSet::FromToml("num_runs = 2\nea_populaton_size = 100\n", {}, "p.toml"); });
  EXPECT_CONTAINS(message, "p.toml line 2");
  EXPECT_CONTAINS(message, "unknown parameter 'ea_populaton_size'");
  EXPECT_CONTAINS(message, "did you mean 'ea_population_size'");

  // A TOML table is not a known key either.
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("[ea]\npopulation_size = 3\n"); }), "unknown parameter 'ea'");
}

TEST(ParameterSet, WrongTypesAreErrors)
{
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("num_runs = \"five\"\n"); }), "must be an integer");
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("ea_num_generations = 5.5\n"); }), "must be an integer");
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("zip = 1\n"); }), "must be a boolean");
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("problem_id = 3\n"); }), "must be a string");
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("morea_sampling_rate = true\n"); }), "must be a number");
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("num_runs = [1, 2]\n"); }), "not a table or array");
  // An integer is a fine real.
  const auto p = ParameterSet::FromToml("morea_sampling_rate = 2\n");
  EXPECT_DOUBLE_EQ(p.GetReal("morea_sampling_rate"), 2.0);
}

TEST(ParameterSet, OutOfRangeValuesAreErrors)
{
  const std::string message = ErrorMessage([] { ParameterSet::FromToml("\nea_population_size = 1\n", {}, "r.toml"); });
  EXPECT_CONTAINS(message, "r.toml line 2");
  EXPECT_CONTAINS(message, "'ea_population_size'");
  EXPECT_CONTAINS(message, "[2, ");
  EXPECT_THROW(ParameterSet::FromToml("ea_adaptive_steering_guidance_threshold = 0.99\n"), Error);
  EXPECT_THROW(ParameterSet::FromToml("morea_max_num_mesh_levels = 7\n"), Error);
  EXPECT_THROW(ParameterSet::FromToml("seed = -1\n"), Error);
  EXPECT_THROW(ParameterSet::FromToml("seed = 3000000000\n"), Error);
  EXPECT_THROW(ParameterSet::FromToml("morea_sampling_rate = nan\n"), Error);
  EXPECT_THROW(ParameterSet::FromToml("preprocess_isotropic_spacing = 0.0\n"), Error);
  // Bounds are inclusive.
  const auto p = ParameterSet::FromToml("ea_population_size = 2\nea_adaptive_steering_guidance_threshold = 1.0\n"
                                        "preprocess_isotropic_spacing = 20.0\n");
  EXPECT_EQ(p.GetInteger("ea_population_size"), 2);
  EXPECT_DOUBLE_EQ(p.GetReal("ea_adaptive_steering_guidance_threshold"), 1.0);
  EXPECT_DOUBLE_EQ(p.GetReal("preprocess_isotropic_spacing"), 20.0);
}

TEST(ParameterSet, BadChoicesAreErrorsListingTheChoices)
{
  const std::string message = ErrorMessage([] { ParameterSet::FromToml("morea_magnitude_metric = \"elastic\"\n"); });
  EXPECT_CONTAINS(message, "\"elastic\"");
  EXPECT_CONTAINS(message, "\"biomechanical\"");
  EXPECT_CONTAINS(message, "\"standard\"");
  EXPECT_THROW(ParameterSet::FromToml("morea_init_noise_method = \"Global-Gaussian\"\n"), Error);
  const auto p = ParameterSet::FromToml("morea_magnitude_metric = \"standard\"\nmorea_repair_method = \"none\"\n");
  EXPECT_EQ(p.GetString("morea_magnitude_metric"), "standard");
  EXPECT_EQ(p.GetString("morea_repair_method"), "none");
  // Free-text keys accept anything.
  EXPECT_EQ(ParameterSet::FromToml("morea_mesh_generation_method = \"anything\"\n")
              .GetString("morea_mesh_generation_method"),
            "anything");
}

TEST(ParameterSet, TomlSyntaxErrorsAndDuplicatesNameTheLine)
{
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("num_runs = 2\nzip = \n", {}, "s.toml"); }), "s.toml line 2");
  EXPECT_CONTAINS(ErrorMessage([] { ParameterSet::FromToml("num_runs = 2\n\nnum_runs = 3\n", {}, "d.toml"); }),
                  "d.toml line 3");
}

// ---------------------------------------------------------------------------
// SetFromString
// ---------------------------------------------------------------------------

TEST(ParameterSet, SetFromStringParsesEachType)
{
  ParameterSet p;
  p.SetFromString("ea_population_size", "100");
  p.SetFromString("morea_sampling_rate", "0.25");
  p.SetFromString("preprocess_intensity_min", "-500");
  p.SetFromString("zip", "true");
  p.SetFromString("problem_guidance_enabled", "0");
  p.SetFromString("problem_id", "with spaces and \"quotes\"");
  EXPECT_EQ(p.GetInteger("ea_population_size"), 100);
  EXPECT_DOUBLE_EQ(p.GetReal("morea_sampling_rate"), 0.25);
  EXPECT_DOUBLE_EQ(p.GetReal("preprocess_intensity_min"), -500.0);
  EXPECT_TRUE(p.GetBool("zip"));
  EXPECT_FALSE(p.GetBool("problem_guidance_enabled"));
  EXPECT_EQ(p.GetString("problem_id"), "with spaces and \"quotes\"");
  EXPECT_TRUE(p.IsExplicit("ea_population_size"));
  EXPECT_TRUE(p.IsExplicit("zip"));
  EXPECT_FALSE(p.IsExplicit("num_runs"));
}

TEST(ParameterSet, SetFromStringRejectsBadValuesAndKeepsTheOldValue)
{
  ParameterSet p;
  EXPECT_CONTAINS(ErrorMessage([&] { p.SetFromString("ea_population_size", "12abc"); }), "expected an integer");
  EXPECT_THROW(p.SetFromString("ea_population_size", ""), Error);
  EXPECT_THROW(p.SetFromString("ea_population_size", "1.5"), Error);
  EXPECT_THROW(p.SetFromString("ea_population_size", "99999999999999999999999"), Error);
  EXPECT_CONTAINS(ErrorMessage([&] { p.SetFromString("ea_population_size", "1"); }), "--set ea_population_size");
  EXPECT_CONTAINS(ErrorMessage([&] { p.SetFromString("morea_sampling_rate", "fast"); }), "expected a number");
  EXPECT_THROW(p.SetFromString("morea_sampling_rate", "1.0x"), Error);
  EXPECT_CONTAINS(ErrorMessage([&] { p.SetFromString("zip", "yes"); }), "expected true or false");
  EXPECT_THROW(p.SetFromString("morea_repair_method", "magic"), Error);
  EXPECT_CONTAINS(ErrorMessage([&] { p.SetFromString("ea_populationsize", "5"); }), "unknown parameter");
  EXPECT_EQ(p.GetInteger("ea_population_size"), 700);
  EXPECT_DOUBLE_EQ(p.GetReal("morea_sampling_rate"), 1.0);
  EXPECT_FALSE(p.GetBool("zip"));
  EXPECT_EQ(p.GetString("morea_repair_method"), "gaussian");
  EXPECT_FALSE(p.IsExplicit("ea_population_size"));
  EXPECT_FALSE(p.IsExplicit("zip"));
}

// ---------------------------------------------------------------------------
// ToToml
// ---------------------------------------------------------------------------

TEST(ParameterSet, ToTomlListsEveryKeyInTableOrder)
{
  const std::string text = ParameterSet().ToToml();
  std::size_t       previous = 0;
  for (const auto & spec : ParameterSet::Specs())
  {
    const auto at = text.find(spec.key + " = ");
    ASSERT_NE(at, std::string::npos) << spec.key;
    EXPECT_GE(at, previous) << spec.key << " out of order";
    previous = at;
  }
  EXPECT_NE(text.find("ea_population_size = 700\n"), std::string::npos);
  EXPECT_NE(text.find("zip = false\n"), std::string::npos);
  EXPECT_NE(text.find("morea_sampling_rate = 1.0\n"), std::string::npos);
  EXPECT_NE(text.find("morea_magnitude_metric = \"biomechanical\"\n"), std::string::npos);
}

TEST(ParameterSet, ToTomlRoundTripsExactly)
{
  // Variables are pasted into the text as is, so a value with quotes comes through --set.
  ParameterSet p = ParameterSet::FromToml(kPaperListing, { { "experiment_descriptor", "x" }, { "problem_id", "p#1" } });
  p.SetFromString("sweep_descriptor", "sweep \"A\" \\ B");
  p.SetFromString("morea_sampling_rate", "0.1");
  p.SetFromString("preprocess_intensity_min", "-1234.5678901234567");
  p.SetFromString("ea_adaptive_steering_guidance_threshold", "123456.75");
  p.SetFromString("preprocess_crop_margin", "1e-300");
  p.SetFromString("preprocess_fov_threshold", "-3e5");
  p.SetFromString("seed", "2147483647");
  p.SetFromString("morea_magnitude_metric", "standard");
  ASSERT_EQ(p.GetString("sweep_descriptor"), "sweep \"A\" \\ B");
  ASSERT_EQ(p.GetString("problem_id"), "p#1");

  const std::string text = p.ToToml();
  ParameterSet      q;
  ASSERT_NO_THROW(q = ParameterSet::FromToml(text)) << text;
  std::string differs;
  EXPECT_TRUE(SameValues(p, q, differs)) << "first difference: " << differs << "\n" << text;
  for (const auto & spec : ParameterSet::Specs())
  {
    EXPECT_TRUE(q.IsExplicit(spec.key)) << spec.key;
  }
  // A default set is a fixed point too.
  EXPECT_EQ(ParameterSet::FromToml(ParameterSet().ToToml()).ToToml(), ParameterSet().ToToml());
}

TEST(ParameterSet, ToTomlRoundTripsDollarSigns)
{
  // A value holding '$' (e.g. from --set) must come back as is, not be taken for a placeholder.
  ParameterSet p;
  p.SetFromString("problem_id", "cost$total");
  ParameterSet q;
  ASSERT_NO_THROW(q = ParameterSet::FromToml(p.ToToml())) << p.ToToml();
  EXPECT_EQ(q.GetString("problem_id"), "cost$total");
}

TEST(ParameterSet, ToTomlRoundTripsStringsWithControlCharacters)
{
  ParameterSet p;
  p.SetFromString("sweep_descriptor", "line one\nline two\ttab\r\x01");
  ParameterSet q;
  ASSERT_NO_THROW(q = ParameterSet::FromToml(p.ToToml())) << p.ToToml();
  EXPECT_EQ(q.GetString("sweep_descriptor"), p.GetString("sweep_descriptor"));
}

TEST(ParameterSet, ToTomlRoundTripsInfinity)
{
  ParameterSet p;
  p.SetFromString("ea_adaptive_steering_guidance_threshold", "inf");
  ASSERT_TRUE(std::isinf(p.GetReal("ea_adaptive_steering_guidance_threshold")));
  const auto q = ParameterSet::FromToml(p.ToToml());
  EXPECT_TRUE(std::isinf(q.GetReal("ea_adaptive_steering_guidance_threshold")));
}

// ---------------------------------------------------------------------------
// RandomGenerator
// ---------------------------------------------------------------------------

TEST(Random, MatchesTheReferenceXoshiro256StarStar)
{
  // Reference values from an independent implementation of SplitMix64 seeding
  // and xoshiro256** (Blackman & Vigna).
  morea_core::RandomGenerator zero(0);
  EXPECT_EQ(zero.NextU64(), 0x99ec5f36cb75f2b4ULL);
  EXPECT_EQ(zero.NextU64(), 0xbf6e1f784956452aULL);
  EXPECT_EQ(zero.NextU64(), 0x1a5f849d4933e6e0ULL);
  morea_core::RandomGenerator fortyTwo(42);
  EXPECT_EQ(fortyTwo.NextU64(), 0x15780b2e0c2ec716ULL);
  EXPECT_EQ(fortyTwo.NextU64(), 0x6104d9866d113a7eULL);
  EXPECT_EQ(fortyTwo.NextU64(), 0xae17533239e499a1ULL);
}

TEST(Random, SameSeedSameSequenceDifferentSeedDifferent)
{
  morea_core::RandomGenerator a(12345), b(12345), c(12346);
  int                    sameAsC = 0;
  for (int i = 0; i < 1000; ++i)
  {
    const auto x = a.NextU64();
    ASSERT_EQ(x, b.NextU64()) << "draw " << i;
    sameAsC += x == c.NextU64();
  }
  EXPECT_EQ(sameAsC, 0);
  // Mixed calls (uniform, normal with its spare value) stay in step too.
  for (int i = 0; i < 1000; ++i)
  {
    ASSERT_EQ(a.Normal(), b.Normal());
    ASSERT_EQ(a.Uniform(-3.0, 5.0), b.Uniform(-3.0, 5.0));
    ASSERT_EQ(a.Normal(), b.Normal());
  }
}

TEST(Random, UniformHasTheRightRangeMeanAndVariance)
{
  morea_core::RandomGenerator g(7);
  const int              n = 200000;
  double                 sum = 0.0, sum2 = 0.0;
  double                 lo = 1.0, hi = 0.0;
  int                    bins[10] = {};
  for (int i = 0; i < n; ++i)
  {
    const double u = g.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    ++bins[static_cast<int>(u * 10)];
  }
  const double mean = sum / n;
  const double variance = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 0.005);
  EXPECT_NEAR(variance, 1.0 / 12.0, 0.002);
  EXPECT_LT(lo, 1e-3);
  EXPECT_GT(hi, 1.0 - 1e-3);
  for (int b : bins)
  {
    EXPECT_NEAR(b, n / 10, n / 100); // each tenth holds 10% +- 1%
  }

  double sumAB = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const double u = g.Uniform(-2.0, 6.0);
    ASSERT_GE(u, -2.0);
    ASSERT_LT(u, 6.0);
    sumAB += u;
  }
  EXPECT_NEAR(sumAB / n, 2.0, 0.04);
}

TEST(Random, NormalIsStandardNormal)
{
  morea_core::RandomGenerator g(2023);
  const int              n = 400000;
  double                 sum = 0.0, sum2 = 0.0, sum3 = 0.0, sum4 = 0.0;
  int                    withinOne = 0, beyondThree = 0;
  for (int i = 0; i < n; ++i)
  {
    const double x = g.Normal();
    ASSERT_TRUE(std::isfinite(x));
    sum += x;
    sum2 += x * x;
    sum3 += x * x * x;
    sum4 += x * x * x * x;
    withinOne += std::abs(x) <= 1.0;
    beyondThree += std::abs(x) > 3.0;
  }
  const double mean = sum / n;
  const double sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_NEAR(sd, 1.0, 0.01);
  EXPECT_NEAR(sum3 / n, 0.0, 0.03);                                   // skewness
  EXPECT_NEAR(sum4 / n, 3.0, 0.08);                                   // kurtosis
  EXPECT_NEAR(static_cast<double>(withinOne) / n, 0.682689, 0.004);   // P(|x| <= 1)
  EXPECT_NEAR(static_cast<double>(beyondThree) / n, 0.0026998, 0.0006); // P(|x| > 3)
}

TEST(Random, NormalPairsAreUncorrelated)
{
  // Box-Muller hands out cos and sin of the same angle in turn: they must be uncorrelated.
  morea_core::RandomGenerator g(99);
  const int              n = 200000;
  double                 sxy = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const double x = g.Normal();
    const double y = g.Normal();
    sxy += x * y;
  }
  EXPECT_NEAR(sxy / n, 0.0, 0.01);
}

TEST(Random, HashCombineIsDeterministicAndOrderSensitive)
{
  EXPECT_EQ(morea_core::HashCombine(1, 2), morea_core::HashCombine(1, 2));
  EXPECT_NE(morea_core::HashCombine(1, 2), morea_core::HashCombine(2, 1));
  EXPECT_NE(morea_core::HashCombine(1, 2), morea_core::HashCombine(1, 3));
  EXPECT_NE(morea_core::HashCombine(0, 0), 0u);
}

TEST(Random, HashCombineHasNoCollisionsForSmallInputs)
{
  // The phantom seeds its noise per slice with HashCombine(seed, stream): phantoms of
  // different seeds must not share noise streams.
  std::set<std::uint64_t> seen;
  for (std::uint64_t seed = 0; seed < 200; ++seed)
    for (std::uint64_t stream = 0; stream < 400; ++stream)
      seen.insert(morea_core::HashCombine(seed, stream));
  EXPECT_EQ(seen.size(), 200u * 400u);
}
