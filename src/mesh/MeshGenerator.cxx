// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/MeshGenerator.h"

#include "ConstraintSurfaces.h"
#include "morea_core/ChildProcess.h"
#include "morea_core/Error.h"
#include "morea_core/MeshPointPlacement.h"
#include "morea_core/ParameterSet.h"
#include "morea_core/StructureSurface.h"
#include "morea_core/Tetrahedralization.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <optional>
#include <stdexcept>

namespace morea_core
{
namespace
{
using Clock = std::chrono::steady_clock;

/** Tetrahedra below this TetrahedronQuality count as slivers. */
constexpr double kSliverQuality = 0.05;

double
SecondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool
InsideShrunk(const Vec3 & p, const MeshDomain & domain, double margin)
{
  for (int a = 0; a < 3; ++a)
    if (p[a] < domain.lower[a] + margin || p[a] > domain.upper[a] - margin)
      return false;
  return true;
}

/** Circumcentre of a tetrahedron; false when it is (nearly) flat. */
bool
Circumcentre(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d, Vec3 & centre)
{
  // Solve 2 (v - a) . x = |v|^2 - |a|^2 for v = b, c, d (Cramer's rule).
  double m[3][3], r[3];
  const Vec3 * v[3] = { &b, &c, &d };
  for (int i = 0; i < 3; ++i)
  {
    r[i] = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      m[i][k] = 2.0 * ((*v[i])[k] - a[k]);
      r[i] += (*v[i])[k] * (*v[i])[k] - a[k] * a[k];
    }
  }
  const auto det3 = [](double x[3][3]) {
    return x[0][0] * (x[1][1] * x[2][2] - x[1][2] * x[2][1]) - x[0][1] * (x[1][0] * x[2][2] - x[1][2] * x[2][0]) +
           x[0][2] * (x[1][0] * x[2][1] - x[1][1] * x[2][0]);
  };
  const double det = det3(m);
  if (std::abs(det) < 1e-12)
    return false;
  for (int k = 0; k < 3; ++k)
  {
    double mk[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        mk[i][j] = (j == k) ? r[i] : m[i][j];
    centre[k] = det3(mk) / det;
  }
  return true;
}

/** Squared length of the longest edge of a tetrahedron. */
double
LongestSquaredEdge(const Vec3 * const (&p)[4])
{
  double longest = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
    {
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k)
        d2 += ((*p[i])[k] - (*p[j])[k]) * ((*p[i])[k] - (*p[j])[k]);
      longest = std::max(longest, d2);
    }
  return longest;
}

/** Up to `count` new points at the circumcentres (or, when those lie outside
 *  the domain, the centroids) of the worst-shaped tetrahedra of quality below
 *  0.2, none closer than a third of the tetrahedron's size to any point. */
std::vector<Vec3>
RefinementPoints(const TetrahedralizationResult & tet, const std::vector<Vec3> & existing, std::size_t count,
                 const MeshDomain & domain, double margin)
{
  std::vector<std::pair<double, std::size_t>> worst;
  for (std::size_t t = 0; t < tet.tetrahedra.size(); ++t)
  {
    const auto & v = tet.tetrahedra[t];
    const double q = TetrahedronQuality(tet.points[v[0]], tet.points[v[1]], tet.points[v[2]], tet.points[v[3]]);
    if (q < 0.2)
      worst.emplace_back(q, t);
  }
  std::sort(worst.begin(), worst.end());
  std::vector<Vec3> added;
  for (const auto & [q, t] : worst)
  {
    if (added.size() == count)
      break;
    const auto & v = tet.tetrahedra[t];
    const Vec3 * p[4] = { &tet.points[v[0]], &tet.points[v[1]], &tet.points[v[2]], &tet.points[v[3]] };
    Vec3         centre;
    if (!Circumcentre(*p[0], *p[1], *p[2], *p[3], centre) || !InsideShrunk(centre, domain, margin))
      for (int k = 0; k < 3; ++k)
        centre[k] = ((*p[0])[k] + (*p[1])[k] + (*p[2])[k] + (*p[3])[k]) / 4.0;
    const double minimum = LongestSquaredEdge(p) / 9.0; // (longest edge / 3)^2
    const auto   tooClose = [&](const std::vector<Vec3> & set) {
      return std::any_of(set.begin(), set.end(), [&](const Vec3 & x) {
        double d2 = 0.0;
        for (int k = 0; k < 3; ++k)
          d2 += (x[k] - centre[k]) * (x[k] - centre[k]);
        return d2 < minimum;
      });
    };
    if (!InsideShrunk(centre, domain, margin) || tooClose(existing) || tooClose(added))
      continue;
    added.push_back(centre);
  }
  return added;
}

/** Splits `total` over `weights` by largest remainders (sums exactly to total). */
std::vector<std::size_t>
Apportion(std::size_t total, const std::vector<double> & weights)
{
  std::vector<std::size_t> parts(weights.size(), 0);
  const double             sum = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (weights.empty() || sum <= 0.0)
    return parts;
  std::vector<std::pair<double, std::size_t>> remainders;
  std::size_t                                 given = 0;
  for (std::size_t i = 0; i < weights.size(); ++i)
  {
    const double exact = static_cast<double>(total) * weights[i] / sum;
    parts[i] = static_cast<std::size_t>(std::floor(exact));
    given += parts[i];
    remainders.emplace_back(-(exact - std::floor(exact)), i);
  }
  std::sort(remainders.begin(), remainders.end());
  for (std::size_t r = 0; given < total; ++r, ++given)
    ++parts[remainders[r % remainders.size()].second];
  return parts;
}

struct PointSet
{
  std::vector<Vec3>         points;
  std::vector<PointOrigin>  origins;
  std::vector<std::int32_t> structures;
  std::vector<BoundaryPin>  pins;

  void
  Add(const std::vector<Vec3> & p, PointOrigin origin, std::int32_t structure, const MeshDomain & domain,
      double pinTolerance)
  {
    for (const Vec3 & x : p)
    {
      points.push_back(x);
      origins.push_back(origin);
      structures.push_back(structure);
      pins.push_back(PinOf(x, domain, pinTolerance));
    }
  }
};

/** How far the tetrahedra fall short of the sliver quality threshold, summed. */
double
SliverShortfall(const TetrahedralizationResult & r)
{
  double sum = 0.0;
  for (const auto & v : r.tetrahedra)
    sum += std::max(0.0, kSliverQuality - TetrahedronQuality(r.points[v[0]], r.points[v[1]], r.points[v[2]], r.points[v[3]]));
  return sum;
}

/** Sliver removal: Delaunay meshes of points on smooth surfaces have flat
 *  tetrahedra wherever four points are nearly cospherical. Nudging one free
 *  vertex of each (contour points by at most a small distance, so they stay
 *  on their contour) and re-meshing removes most; a pass is kept only when
 *  it lowers the total shortfall below the quality threshold. */
void
RemoveSlivers(PointSet & set, TetrahedralizationResult & tet,
              const std::function<TetrahedralizationResult(bool trial)> & tetrahedralize, RandomGenerator & random,
              const MeshDomain & domain, double margin, double contourJitter)
{
  double currentBadness = SliverShortfall(tet);
  for (std::size_t pass = 0; pass < 60 && currentBadness > 0.0; ++pass)
  {
    const std::vector<Vec3> saved = set.points;
    std::vector<bool>       moved(set.points.size(), false);
    for (const auto & v : tet.tetrahedra)
    {
      const Vec3 * p[4] = { &tet.points[v[0]], &tet.points[v[1]], &tet.points[v[2]], &tet.points[v[3]] };
      if (TetrahedronQuality(*p[0], *p[1], *p[2], *p[3]) >= kSliverQuality)
        continue;
      // The freest vertex: random, refinement or shell, then face, then contour points.
      int best = -1, bestRank = 99;
      for (int k = 0; k < 4; ++k)
      {
        const std::uint32_t i = v[k];
        if (i >= set.points.size() || moved[i])
          continue;
        const PointOrigin o = set.origins[i];
        const bool free = o == PointOrigin::Random || o == PointOrigin::Refinement || o == PointOrigin::Shell;
        const int  rank = free                             ? 0
                          : o == PointOrigin::BoundaryFace ? 1
                          : o == PointOrigin::Contour      ? 2
                                                           : 99;
        if (rank < bestRank)
        {
          bestRank = rank;
          best = k;
        }
      }
      if (best < 0 || bestRank == 99)
        continue;
      const std::uint32_t i = v[best];
      const double longest = std::sqrt(LongestSquaredEdge(p));
      const double sigma = bestRank == 2 ? std::min(0.1 * longest, contourJitter) : 0.1 * longest;
      Vec3         q = set.points[i];
      for (int k = 0; k < 3; ++k)
        q[k] += sigma * random.Normal();
      const bool onFace = set.origins[i] == PointOrigin::BoundaryFace;
      for (int k = 0; k < 3; ++k)
        if (!onFace || set.pins[i][k] == 0)
          q[k] = std::clamp(q[k], domain.lower[k] + margin, domain.upper[k] - margin);
      set.points[i] = ProjectToDomain(q, set.pins[i], domain);
      moved[i] = true;
    }
    std::optional<TetrahedralizationResult> trial;
    try
    {
      trial = tetrahedralize(true);
    }
    catch (const Error &)
    {
      // TetGen failed on the moved points with the surfaces: keep the last mesh.
    }
    const double trialBadness = trial ? SliverShortfall(*trial) : currentBadness;
    if (trialBadness < currentBadness)
    {
      tet = std::move(*trial);
      currentBadness = trialBadness;
    }
    else
    {
      set.points = saved;
    }
  }
}

/** What tetrahedralisation, refinement and sliver removal need of GenerateMesh. */
struct PhaseInputs
{
  const MeshDomain &                     domain;
  double                                 margin, pinTolerance, contourJitter;
  std::size_t                            refinementBudget;
  std::function<Vec3(RandomGenerator &)> drawInside;
};

/** A TetGen failure in a strict phase: not a morea_core::Error, so that sliver
 *  removal does not take it for a trial that failed. */
struct StrictPhaseFailure : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/** Tetrahedralises `set`, then spends the refinement budget and removes
 *  slivers, re-tetrahedralising each time. Not strict: TetGen runs as
 *  `constrained` says, and a failure drops surfaces (notes in `report`).
 *  Strict: the first failure is thrown as StrictPhaseFailure. */
TetrahedralizationResult
RunPhase(PointSet & set, ConstrainedTetrahedralization & constrained, RandomGenerator & random,
         const PhaseInputs & in, bool strict, MeshGenerationReport & report)
{
  // A failure falls back to fewer surfaces, then none, rather than fail the
  // run; a trial (sliver removal) fails instead: it is simply not taken.
  const auto tetrahedralize = [&](bool trial) {
    if (!strict)
      return constrained.Run(set.points, !trial, report.notes);
    try
    {
      return constrained.Run(set.points, false, report.notes);
    }
    catch (const Error & e)
    {
      throw StrictPhaseFailure(e.what());
    }
  };
  TetrahedralizationResult tet = tetrahedralize(false);

  // Refinement: the rest of the budget goes, a few at a time, to the
  // circumcentres of the worst tetrahedra (which destroys them, the new point
  // lying inside their circumsphere).
  for (std::size_t left = in.refinementBudget; left > 0;)
  {
    const std::size_t batch = std::max<std::size_t>(1, (in.refinementBudget + 3) / 4);
    std::vector<Vec3> added = RefinementPoints(tet, set.points, std::min(batch, left), in.domain, in.margin);
    if (added.empty())
    {
      added = BestCandidateRandomPoints(left, in.drawInside, set.points, random);
      set.Add(added, PointOrigin::Random, -1, in.domain, in.pinTolerance);
      report.randomPoints += left;
      left = 0;
    }
    else
    {
      set.Add(added, PointOrigin::Refinement, -1, in.domain, in.pinTolerance);
      report.refinementPoints += added.size();
      left -= added.size();
    }
    tet = tetrahedralize(false);
  }
  RemoveSlivers(set, tet, tetrahedralize, random, in.domain, in.margin, in.contourJitter);
  return tet;
}

// What a phase run in a child sends back: the point set and the mesh.
template <typename T>
void
AppendVector(std::string & bytes, const std::vector<T> & v)
{
  const std::uint64_t n = v.size();
  bytes.append(reinterpret_cast<const char *>(&n), sizeof n);
  bytes.append(reinterpret_cast<const char *>(v.data()), v.size() * sizeof(T));
}
template <typename T>
std::vector<T>
ReadVector(const std::string & bytes, std::size_t & at)
{
  std::uint64_t n = 0;
  if (bytes.size() - at < sizeof n)
    throw Error("mesh generation: a child process sent a short answer");
  std::memcpy(&n, bytes.data() + at, sizeof n);
  at += sizeof n;
  if ((bytes.size() - at) / sizeof(T) < n)
    throw Error("mesh generation: a child process sent a short answer");
  std::vector<T> v(n);
  std::memcpy(v.data(), bytes.data() + at, n * sizeof(T));
  at += n * sizeof(T);
  return v;
}

/** RunPhase isolated from TetGen's crashes at the cost of one process:
 *  the whole phase runs strictly in a child, TetGen in that child's own
 *  process; only when it fails there (TetGen failed, or crashed on an error)
 *  does it run again here with each TetGen run in a child of its own, where
 *  surfaces can be dropped and sliver trials fail. Both give the same mesh
 *  when nothing fails (the child works on a copy of the same state). A fork
 *  costs about 13 ms per 300 MB of the process on the development machine,
 *  and a mesh takes about 60 TetGen runs. */
TetrahedralizationResult
TetrahedralizeAndRefine(PointSet & set, ConstrainedTetrahedralization & constrained, RandomGenerator & random,
                        const PhaseInputs & in, MeshGenerationReport & report, const TetrahedralizationOptions & options)
{
  if (!options.isolated || !ChildProcessesAvailable())
    return RunPhase(set, constrained, random, in, false, report);
  TetrahedralizationOptions inProcess = options;
  inProcess.isolated = false;
  inProcess.noRetryAfterFailure = true;
  // The phase's some 60 runs take about 0.25 s for 600 points; three runs'
  // time-outs leave room enough and stop a run that loops for ever sooner.
  const double perRun = options.TimeoutFor(set.points.size());
  const ChildResult child = RunInChildProcess(
    [&]() {
      ConstrainedTetrahedralization here = constrained.WithOptions(inProcess);
      MeshGenerationReport          counts;
      const TetrahedralizationResult tet = RunPhase(set, here, random, in, true, counts);
      std::string                    bytes;
      const std::uint64_t            numbers[3] = { counts.randomPoints, counts.refinementPoints, tet.steinerPoints };
      bytes.append(reinterpret_cast<const char *>(numbers), sizeof numbers);
      AppendVector(bytes, set.points);
      AppendVector(bytes, set.origins);
      AppendVector(bytes, set.structures);
      AppendVector(bytes, set.pins);
      AppendVector(bytes, tet.points);
      AppendVector(bytes, tet.tetrahedra);
      return bytes;
    },
    3.0 * perRun);
  if (!child.ok)
    return RunPhase(set, constrained, random, in, false, report);
  std::uint64_t numbers[3];
  if (child.bytes.size() < sizeof numbers)
    throw Error("mesh generation: a child process sent a short answer");
  std::memcpy(numbers, child.bytes.data(), sizeof numbers);
  std::size_t at = sizeof numbers;
  PointSet    result;
  result.points = ReadVector<Vec3>(child.bytes, at);
  result.origins = ReadVector<PointOrigin>(child.bytes, at);
  result.structures = ReadVector<std::int32_t>(child.bytes, at);
  result.pins = ReadVector<BoundaryPin>(child.bytes, at);
  TetrahedralizationResult tet;
  tet.points = ReadVector<Vec3>(child.bytes, at);
  tet.tetrahedra = ReadVector<Tetrahedron>(child.bytes, at);
  tet.steinerPoints = numbers[2];
  set = std::move(result);
  report.randomPoints += numbers[0];
  report.refinementPoints += numbers[1];
  return tet;
}
} // namespace

MeshGeneratorOptions
MeshGeneratorOptions::FromParameters(const ParameterSet & parameters)
{
  MeshGeneratorOptions options;
  options.numberOfPoints = static_cast<std::size_t>(parameters.GetInteger("morea_mesh_num_points"));
  options.boundaryFraction = parameters.GetReal("morea_mesh_boundary_fraction");
  options.seed = static_cast<std::uint64_t>(parameters.GetInteger("seed"));
  for (const auto & [name, share] : ParseNamedValues(parameters.GetString("morea_mesh_structure_shares"),
                                                      "morea_mesh_structure_shares"))
  {
    if (share < 0.0)
      throw Error("parameter morea_mesh_structure_shares: share of " + name + " is negative");
    options.shares[name] = share;
  }
  options.shellOffsets.clear();
  for (const std::string & item : ParseNameList(parameters.GetString("morea_mesh_shell_offsets")))
  {
    std::size_t used = 0;
    double      offset = 0.0;
    try
    {
      offset = std::stod(item, &used);
    }
    catch (const std::exception &)
    {
      used = 0;
    }
    if (used != item.size() || !(offset > 0.0) || !std::isfinite(offset))
      throw Error("parameter morea_mesh_shell_offsets: \"" + item + "\" is not a positive distance in mm");
    options.shellOffsets.push_back(offset);
  }
  options.shellFraction = parameters.GetReal("morea_mesh_shell_fraction");
  options.shellStructures = ParseNameList(parameters.GetString("morea_mesh_shell_structures"));

  // Method names follow the paper: annotation-group[-random][-bladder][-<percent random>].
  const std::string & method = parameters.GetString("morea_mesh_generation_method");
  const auto          bad = [&]() {
    return Error("parameter morea_mesh_generation_method: \"" + method +
                 "\" is not one of random, annotation-group[-random][-bladder][-<percent>]");
  };
  std::vector<std::string> tokens;
  for (std::size_t start = 0;;)
  {
    const auto dash = method.find('-', start);
    tokens.push_back(method.substr(start, dash == std::string::npos ? std::string::npos : dash - start));
    if (dash == std::string::npos)
      break;
    start = dash + 1;
  }
  if (tokens.size() == 1 && tokens[0] == "random")
  {
    options.useContourPoints = false;
    options.randomFraction = 1.0;
    options.surfaceStructures.clear();
    return options;
  }
  if (tokens.size() < 2 || tokens[0] != "annotation" || tokens[1] != "group")
    throw bad();
  bool useSurfaces = false;
  bool random = false;
  options.randomFraction = 0.0;
  for (std::size_t i = 2; i < tokens.size(); ++i)
  {
    if (tokens[i] == "random")
      random = true;
    else if (tokens[i] == "bladder")
      useSurfaces = true;
    else if (i + 1 == tokens.size() && random && !tokens[i].empty() &&
             tokens[i].find_first_not_of("0123456789") == std::string::npos && std::stoi(tokens[i]) <= 100)
      options.randomFraction = std::stoi(tokens[i]) / 100.0;
    else
      throw bad();
  }
  if (random && options.randomFraction == 0.0)
    options.randomFraction = 0.10;
  options.surfaceStructures =
    useSurfaces ? ParseNameList(parameters.GetString("morea_mesh_surface_structures")) : std::vector<std::string>{};
  return options;
}

TetrahedralMesh
GenerateMesh(const MeshDomain & domain, const std::vector<MeshStructure> & structures,
             const MeshGeneratorOptions & options, MeshGenerationReport * reportOut)
{
  MeshGenerationReport report;
  const Vec3           extent = domain.Extent();
  const double         minExtent = std::min({ extent[0], extent[1], extent[2] });
  const double         maxExtent = std::max({ extent[0], extent[1], extent[2] });
  if (!(minExtent > 0.0))
    throw Error("mesh domain is empty or flat");
  const std::size_t total = options.numberOfPoints;
  if (total < 8)
    throw Error("a mesh needs at least 8 points (the domain's corners)");
  // Inner points keep a small distance from the faces (no flat slivers there)
  // and from each other (TetGen would merge duplicates).
  const double margin = 0.005 * minExtent;
  const double minimumDistance = 1e-3 * maxExtent;
  const double pinTolerance = 1e-9 * maxExtent;
  // Contour points of a structure cut by the domain boundary would sit right
  // next to the faces and make flat tetrahedra with the face points there.
  const double contourGap = 0.03 * minExtent;
  const double contourJitter = 0.01 * minExtent; // largest nudge of a contour point (sliver removal)
  RandomGenerator random(HashCombine(options.seed, 0x6d657368ull)); // "mesh"

  auto     start = Clock::now();
  PointSet set;
  set.Add(DomainCorners(domain), PointOrigin::Corner, -1, domain, pinTolerance);
  report.corners = 8;

  // Contour candidates inside the domain, per structure.
  std::vector<std::vector<Vec3>> candidates(structures.size());
  std::vector<double>            weights(structures.size(), 0.0);
  for (std::size_t s = 0; s < structures.size() && options.useContourPoints; ++s)
  {
    for (const Vec3 & p : structures[s].contourPoints)
      if (InsideShrunk(p, domain, contourGap))
        candidates[s].push_back(p);
    const auto it = options.shares.find(structures[s].name);
    weights[s] = candidates[s].empty() ? 0.0 : (it == options.shares.end() ? 1.0 : it->second);
  }
  for (const auto & [name, share] : options.shares)
  {
    if (std::none_of(structures.begin(), structures.end(), [&](const MeshStructure & m) { return m.name == name; }))
      report.notes.push_back("mesh share given for unknown structure " + name);
  }
  const std::size_t randomTarget =
    options.useContourPoints ? static_cast<std::size_t>(std::lround(options.randomFraction * static_cast<double>(total)))
                             : total - 8;
  const std::size_t shellTarget =
    options.useContourPoints && !options.shellOffsets.empty()
      ? static_cast<std::size_t>(std::lround(options.shellFraction * static_cast<double>(total)))
      : 0;
  const std::size_t structureBudget = total - 8 - std::min(randomTarget + shellTarget, total - 8);
  std::vector<std::size_t> quota = Apportion(structureBudget, weights);
  report.secondsPlacement += SecondsSince(start);

  // Surfaces first: their decimated vertices replace the structure's contour points.
  start = Clock::now();
  ConstrainedTetrahedralization constrained(options.tetrahedralization);
  std::vector<TriangleSurface>  accepted; // the surfaces so far, which a later one may not meet
  std::vector<bool>             hasSurface(structures.size(), false);
  for (std::size_t s = 0; s < structures.size(); ++s)
  {
    const MeshStructure & st = structures[s];
    if (std::find(options.surfaceStructures.begin(), options.surfaceStructures.end(), st.name) ==
          options.surfaceStructures.end() ||
        quota[s] < 4)
      continue;
    if (st.mask == nullptr)
    {
      report.notes.push_back("no mask for the surface of " + st.name + "; its contour points are used instead");
      continue;
    }
    std::optional<TriangleSurface> surface =
      PrepareConstraintSurface(st.name, *st.mask, domain, quota[s], margin, accepted, report.notes);
    if (!surface)
      continue;
    const auto offset = static_cast<std::uint32_t>(set.points.size());
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (const auto & t : surface->triangles)
      triangles.push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
    constrained.AddSurface(st.name, std::move(triangles));
    set.Add(surface->vertices, PointOrigin::Surface, static_cast<std::int32_t>(s), domain, pinTolerance);
    hasSurface[s] = true;
    report.surfacePoints += surface->vertices.size();
    report.surfaceTriangles += surface->triangles.size();
    report.pointsPerStructure.emplace_back(st.name, surface->vertices.size());
    accepted.push_back(std::move(*surface));
  }
  report.secondsSurfaces = SecondsSince(start);

  // Contour points share what the surfaces left of the structure budget.
  start = Clock::now();
  const std::size_t usedBySurfaces = report.surfacePoints;
  for (std::size_t s = 0; s < structures.size(); ++s)
    if (hasSurface[s])
      weights[s] = 0.0;
  quota = Apportion(structureBudget > usedBySurfaces ? structureBudget - usedBySurfaces : 0, weights);
  for (std::size_t s = 0; s < structures.size(); ++s)
  {
    if (hasSurface[s] || quota[s] == 0)
      continue;
    const std::vector<Vec3> chosen = SpreadOutSubset(candidates[s], quota[s], set.points, minimumDistance);
    set.Add(chosen, PointOrigin::Contour, static_cast<std::int32_t>(s), domain, pinTolerance);
    report.contourPoints += chosen.size();
    report.pointsPerStructure.emplace_back(structures[s].name, chosen.size());
  }

  // Shells around the deforming organs, spread out like contour points; what
  // they cannot use (a shell outside the domain) goes to the random points.
  if (shellTarget > 0)
  {
    std::vector<std::vector<Vec3>> shells; // candidates per structure and offset
    for (std::size_t s = 0; s < structures.size(); ++s)
    {
      if (std::find(options.shellStructures.begin(), options.shellStructures.end(), structures[s].name) ==
          options.shellStructures.end())
        continue;
      if (structures[s].mask == nullptr)
      {
        report.notes.push_back("no mask for the shells around " + structures[s].name + "; none placed there");
        continue;
      }
      const Volume<float> distance = DistanceToMask(*structures[s].mask);
      for (const double offset : options.shellOffsets)
      {
        std::vector<Vec3> inside;
        for (const Vec3 & p : ShellPoints(distance, offset))
          if (InsideShrunk(p, domain, contourGap))
            inside.push_back(p);
        if (inside.empty())
          report.notes.push_back("the shell " + std::to_string(std::lround(offset)) + " mm around " + structures[s].name +
                                 " lies outside the domain");
        else
          shells.push_back(std::move(inside));
      }
    }
    if (shells.empty())
      report.notes.push_back("no shell around any structure (morea_mesh_shell_structures names none with a "
                             "mask): those points are random");
    const std::vector<std::size_t> shellQuota =
      Apportion(std::min(shellTarget, total > set.points.size() ? total - set.points.size() : 0),
                std::vector<double>(shells.size(), 1.0));
    for (std::size_t i = 0; i < shells.size(); ++i)
    {
      const std::vector<Vec3> chosen = SpreadOutSubset(shells[i], shellQuota[i], set.points, minimumDistance);
      set.Add(chosen, PointOrigin::Shell, -1, domain, pinTolerance);
      report.shellPoints += chosen.size();
    }
  }

  // Random points fill up to the requested count: some on the faces, the rest inside.
  if (set.points.size() > total)
    throw Error("the structure surfaces alone have more vertices than morea_mesh_num_points");
  const std::size_t randomCount = total - set.points.size();
  const auto faces = static_cast<std::size_t>(std::lround(options.boundaryFraction * static_cast<double>(randomCount)));
  const double      faceArea[3] = { extent[1] * extent[2], extent[0] * extent[2], extent[0] * extent[1] };
  const auto        drawOnFace = [&](RandomGenerator & r) {
    double pick = r.Uniform(0.0, faceArea[0] + faceArea[1] + faceArea[2]);
    int    axis = 0;
    while (axis < 2 && pick >= faceArea[axis])
      pick -= faceArea[axis++];
    Vec3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = r.Uniform(domain.lower[a] + margin, domain.upper[a] - margin);
    p[axis] = r.Uniform() < 0.5 ? domain.lower[axis] : domain.upper[axis];
    return p;
  };
  const auto drawInside = [&](RandomGenerator & r) {
    Vec3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = r.Uniform(domain.lower[a] + margin, domain.upper[a] - margin);
    return p;
  };
  set.Add(BestCandidateRandomPoints(faces, drawOnFace, set.points, random), PointOrigin::BoundaryFace, -1, domain,
          pinTolerance);
  const std::size_t inner = randomCount - faces;
  const auto        refinementBudget =
    static_cast<std::size_t>(std::lround(options.refinementFraction * static_cast<double>(inner)));
  set.Add(BestCandidateRandomPoints(inner - refinementBudget, drawInside, set.points, random), PointOrigin::Random,
          -1, domain, pinTolerance);
  report.boundaryPoints = faces;
  report.randomPoints = inner - refinementBudget;
  report.secondsPlacement += SecondsSince(start);

  start = Clock::now();
  PhaseInputs inputs{ domain, margin, pinTolerance, contourJitter, refinementBudget, drawInside };
  TetrahedralizationResult tet =
    TetrahedralizeAndRefine(set, constrained, random, inputs, report, options.tetrahedralization);
  report.secondsTetrahedralization = SecondsSince(start);

  TetrahedralMesh mesh;
  mesh.domain = domain;
  mesh.points = std::move(tet.points);
  mesh.tetrahedra = std::move(tet.tetrahedra);
  mesh.origins = std::move(set.origins);
  mesh.structures = std::move(set.structures);
  mesh.pins = std::move(set.pins);
  mesh.constrainedFaces = constrained.Triangles();
  for (std::size_t i = mesh.origins.size(); i < mesh.points.size(); ++i)
  {
    mesh.origins.push_back(PointOrigin::Steiner);
    mesh.structures.push_back(-1);
    mesh.pins.push_back(PinOf(mesh.points[i], domain, pinTolerance));
  }
  report.steinerPoints = tet.steinerPoints;
  report.tetrahedra = mesh.tetrahedra.size();
  report.worstQuality = 1.0;
  for (const Tetrahedron & t : mesh.tetrahedra)
  {
    const double q = TetrahedronQuality(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]);
    report.worstQuality = std::min(report.worstQuality, q);
    report.slivers += q < kSliverQuality;
  }

  // The mesh must tile the domain box exactly (no holes, no overlaps).
  double volume = 0.0;
  for (const Tetrahedron & t : mesh.tetrahedra)
    volume += SignedVolume(t, mesh.points);
  const double boxVolume = extent[0] * extent[1] * extent[2];
  if (std::abs(volume - boxVolume) > 1e-6 * boxVolume)
    throw Error("the generated mesh does not tile the domain (volume " + std::to_string(volume) + " of " +
                std::to_string(boxVolume) + " mm^3)");
  if (reportOut)
    *reportOut = report;
  return mesh;
}
} // namespace morea_core
