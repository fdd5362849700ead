// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/Tetrahedralization.h"

#include "morea_core/ChildProcess.h"
#include "morea_core/Error.h"

#include <tetgen.h>

#include <cmath>
#include <cstring>
#include <string>

namespace morea_core
{
namespace
{
// tetgenio frees its arrays with delete[] in its destructor, so inputs are
// allocated with new[] and handed over.
void
FillInput(tetgenio & in, const std::vector<Vec3> & points, const std::vector<std::array<std::uint32_t, 3>> & triangles)
{
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(points.size());
  in.pointlist = new REAL[points.size() * 3];
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      in.pointlist[3 * i + a] = points[i][a];
    }
  }
  if (triangles.empty())
  {
    return;
  }
  in.numberoffacets = static_cast<int>(triangles.size());
  in.facetlist = new tetgenio::facet[triangles.size()];
  in.facetmarkerlist = new int[triangles.size()];
  for (std::size_t f = 0; f < triangles.size(); ++f)
  {
    tetgenio::facet & facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int v = 0; v < 3; ++v)
    {
      facet.polygonlist[0].vertexlist[v] = static_cast<int>(triangles[f][v]);
    }
    in.facetmarkerlist[f] = 1;
  }
}

bool
Run(const char * switches, tetgenio & in, tetgenio & out, std::string & failure)
{
  tetgenbehavior behaviour;
  std::string    s(switches);
  if (!behaviour.parse_commandline(&s[0]))
  {
    failure = "bad TetGen switches";
    return false;
  }
  try
  {
    tetrahedralize(&behaviour, &in, &out);
  }
  catch (int code) // TetGen's library build reports errors by throwing an int
  {
    static const char * const reasons[] = { "",
                                            "out of memory",
                                            "internal error",
                                            "self-intersecting constraint surfaces",
                                            "a very small input feature size",
                                            "a very close point pair",
                                            "an invalid input" };
    failure = (code >= 1 && code <= 6) ? reasons[code] : "error " + std::to_string(code);
    return false;
  }
  return true;
}
/** One TetGen run with `switches`, and the result with positively oriented
 *  tetrahedra; throws Error when TetGen reports an error. */
TetrahedralizationResult
RunTetGen(const char * switches, const std::vector<Vec3> & points,
          const std::vector<std::array<std::uint32_t, 3>> & constraintTriangles)
{
  tetgenio    in, out;
  std::string failure;
  FillInput(in, points, constraintTriangles);
  if (!Run(switches, in, out, failure))
    throw Error(failure);
  if (out.numberofpoints < static_cast<int>(points.size()))
  {
    // TetGen drops duplicate points; the caller's indices would no longer match.
    throw Error("TetGen merged " + std::to_string(points.size() - static_cast<std::size_t>(out.numberofpoints)) +
                " duplicate mesh points");
  }
  TetrahedralizationResult result;
  result.points.resize(static_cast<std::size_t>(out.numberofpoints));
  for (std::size_t i = 0; i < result.points.size(); ++i)
  {
    result.points[i] = { out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2] };
  }
  result.steinerPoints = result.points.size() - points.size();
  result.tetrahedra.reserve(static_cast<std::size_t>(out.numberoftetrahedra));
  for (int t = 0; t < out.numberoftetrahedra; ++t)
  {
    const int * c = out.tetrahedronlist + static_cast<std::size_t>(t) * static_cast<std::size_t>(out.numberofcorners);
    Tetrahedron tet{ { static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]),
                       static_cast<std::uint32_t>(c[2]), static_cast<std::uint32_t>(c[3]) } };
    const double v = SignedVolume(tet, result.points);
    if (v == 0.0)
    {
      continue; // a flat sliver on coplanar hull points encloses nothing
    }
    if (v < 0.0)
    {
      std::swap(tet[2], tet[3]);
    }
    result.tetrahedra.push_back(tet);
  }
  return result;
}

// The result through the child's pipe: counts, then the arrays as they lie in memory.
std::string
Serialise(const TetrahedralizationResult & r)
{
  const std::uint64_t header[3] = { r.points.size(), r.tetrahedra.size(), r.steinerPoints };
  std::string         bytes(reinterpret_cast<const char *>(header), sizeof header);
  bytes.append(reinterpret_cast<const char *>(r.points.data()), r.points.size() * sizeof(Vec3));
  bytes.append(reinterpret_cast<const char *>(r.tetrahedra.data()), r.tetrahedra.size() * sizeof(Tetrahedron));
  return bytes;
}

TetrahedralizationResult
Deserialise(const std::string & bytes)
{
  std::uint64_t header[3];
  if (bytes.size() < sizeof header)
    throw Error("TetGen's child process sent a short answer");
  std::memcpy(header, bytes.data(), sizeof header);
  if (bytes.size() != sizeof header + header[0] * sizeof(Vec3) + header[1] * sizeof(Tetrahedron))
    throw Error("TetGen's child process sent an answer of the wrong size");
  TetrahedralizationResult r;
  r.points.resize(header[0]);
  r.tetrahedra.resize(header[1]);
  r.steinerPoints = header[2];
  std::memcpy(r.points.data(), bytes.data() + sizeof header, r.points.size() * sizeof(Vec3));
  std::memcpy(r.tetrahedra.data(), bytes.data() + sizeof header + r.points.size() * sizeof(Vec3),
              r.tetrahedra.size() * sizeof(Tetrahedron));
  return r;
}
} // namespace

TetrahedralizationResult
Tetrahedralize(const std::vector<Vec3> & points, const std::vector<std::array<std::uint32_t, 3>> & constraintTriangles,
               const TetrahedralizationOptions & options)
{
  if (points.size() < 4)
  {
    throw Error("tetrahedralisation needs at least 4 points, got " + std::to_string(points.size()));
  }
  for (const auto & t : constraintTriangles)
  {
    for (std::uint32_t v : t)
    {
      if (v >= points.size())
      {
        throw Error("constraint triangle refers to point " + std::to_string(v) + " of " +
                    std::to_string(points.size()));
      }
    }
  }

  // Q quiet, z zero-based. With constraints: p reads them as a piecewise
  // linear complex, c keeps the whole convex hull (the domain box) instead of
  // carving the outside of the surfaces away, Y first forbids Steiner points
  // on the constraints so the surfaces' vertices stay the mesh points.
  // Each attempt runs in a child process when asked to (ChildProcess.h: an
  // error inside TetGen 1.5 corrupts its heap), so a crash is one more failure.
  const double timeout = options.TimeoutFor(points.size());
  std::string failure;
  for (const char * switches : constraintTriangles.empty() ? std::vector<const char *>{ "Qz" }
                                                           : std::vector<const char *>{ "pcYQz", "pcQz" })
  {
    if (!options.isolated)
    {
      try
      {
        return RunTetGen(switches, points, constraintTriangles);
      }
      catch (const Error & e)
      {
        if (options.noRetryAfterFailure)
          throw;
        failure = e.what();
        continue;
      }
    }
    const ChildResult child = RunInChildProcess(
      [&]() { return Serialise(RunTetGen(switches, points, constraintTriangles)); }, timeout);
    if (child.ok)
      return Deserialise(child.bytes);
    failure = child.crashed ? "TetGen " + child.failure +
                                (constraintTriangles.empty()
                                   ? std::string()
                                   : "; TetGen 1.5 crashes on the errors it finds, such as constraint "
                                     "triangles that intersect or nearly touch")
              : child.timedOut ? "TetGen " + child.failure
                               : child.failure;
  }
  throw Error("TetGen could not tetrahedralise the mesh points: " + failure);
}
} // namespace morea_core
