// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "morea_core/SurfaceCheck.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace morea_core
{
namespace
{
Vec3
Sub(const Vec3 & a, const Vec3 & b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
Vec3
Cross(const Vec3 & a, const Vec3 & b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
double
Dot(const Vec3 & a, const Vec3 & b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
/** Sign of the volume of (a, b, c, d): which side of plane abc d is on. */
int
Orient(const Vec3 & a, const Vec3 & b, const Vec3 & c, const Vec3 & d)
{
  const double v = Dot(Cross(Sub(b, a), Sub(c, a)), Sub(d, a));
  return (v > 0.0) - (v < 0.0);
}

// Coplanar tests in 2D: the plane is projected along its normal's largest axis.
using Vec2 = std::array<double, 2>;
int
Orient2(const Vec2 & a, const Vec2 & b, const Vec2 & c)
{
  const double v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  return (v > 0.0) - (v < 0.0);
}
bool
OnSegment2(const Vec2 & a, const Vec2 & b, const Vec2 & p) // p collinear with ab
{
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
         p[1] <= std::max(a[1], b[1]);
}
bool
SegmentsMeet2(const Vec2 & p, const Vec2 & q, const Vec2 & a, const Vec2 & b)
{
  const int o1 = Orient2(p, q, a), o2 = Orient2(p, q, b), o3 = Orient2(a, b, p), o4 = Orient2(a, b, q);
  if (o1 != o2 && o3 != o4 && o1 * o2 <= 0 && o3 * o4 <= 0)
    return true;
  return (o1 == 0 && OnSegment2(p, q, a)) || (o2 == 0 && OnSegment2(p, q, b)) || (o3 == 0 && OnSegment2(a, b, p)) ||
         (o4 == 0 && OnSegment2(a, b, q));
}
bool
InsideTriangle2(const Vec2 & p, const Vec2 (&t)[3])
{
  const int a = Orient2(t[0], t[1], p), b = Orient2(t[1], t[2], p), c = Orient2(t[2], t[0], p);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}
struct Projection
{
  int u{ 0 }, v{ 1 };
  explicit Projection(const Vec3 & normal)
  {
    const int drop = std::abs(normal[0]) >= std::abs(normal[1]) && std::abs(normal[0]) >= std::abs(normal[2]) ? 0
                     : std::abs(normal[1]) >= std::abs(normal[2])                                            ? 1
                                                                                                             : 2;
    u = drop == 0 ? 1 : 0;
    v = drop == 2 ? 1 : 2;
  }
  Vec2
  operator()(const Vec3 & p) const
  {
    return { p[u], p[v] };
  }
};

/** Segment pq against triangle t in t's plane (p and q lie in it). */
bool
CoplanarSegmentMeetsTriangle(const Vec3 & p, const Vec3 & q, const Vec3 * const (&t)[3])
{
  const Projection P(Cross(Sub(*t[1], *t[0]), Sub(*t[2], *t[0])));
  const Vec2       tri[3] = { P(*t[0]), P(*t[1]), P(*t[2]) };
  const Vec2       a = P(p), b = P(q);
  if (InsideTriangle2(a, tri) || InsideTriangle2(b, tri))
    return true;
  for (int e = 0; e < 3; ++e)
    if (SegmentsMeet2(a, b, tri[e], tri[(e + 1) % 3]))
      return true;
  return false;
}

/** Whether segment pq meets triangle t (touching counts). */
bool
SegmentMeetsTriangle(const Vec3 & p, const Vec3 & q, const Vec3 * const (&t)[3])
{
  const int sp = Orient(*t[0], *t[1], *t[2], p), sq = Orient(*t[0], *t[1], *t[2], q);
  if (sp * sq > 0)
    return false;
  if (sp == 0 && sq == 0)
    return CoplanarSegmentMeetsTriangle(p, q, t);
  const int a = Orient(p, q, *t[0], *t[1]), b = Orient(p, q, *t[1], *t[2]), c = Orient(p, q, *t[2], *t[0]);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

/** Whether two triangles without a common vertex meet: an edge of one meets the other. */
bool
TrianglesMeet(const Vec3 * const (&s)[3], const Vec3 * const (&t)[3])
{
  for (int e = 0; e < 3; ++e)
  {
    if (SegmentMeetsTriangle(*s[e], *s[(e + 1) % 3], t) || SegmentMeetsTriangle(*t[e], *t[(e + 1) % 3], s))
      return true;
  }
  return false;
}

/** Triangles s and t share vertex s[i] == t[j] only: whether they meet anywhere
 *  else. The edges at the shared vertex are tested from just beside it. */
bool
TrianglesMeetBesideVertex(const Vec3 * const (&s)[3], int i, const Vec3 * const (&t)[3], int j)
{
  const auto besides = [](const Vec3 & from, const Vec3 & to) {
    Vec3 p;
    for (int k = 0; k < 3; ++k)
      p[k] = from[k] + 1e-6 * (to[k] - from[k]);
    return p;
  };
  const Vec3 * const (*tri[2])[3] = { &s, &t };
  const int          at[2] = { i, j };
  for (int side = 0; side < 2; ++side)
  {
    const auto & a = *tri[side];
    const auto & b = *tri[1 - side];
    const int    v = at[side];
    const Vec3 & p = *a[(v + 1) % 3];
    const Vec3 & q = *a[(v + 2) % 3];
    if (SegmentMeetsTriangle(p, q, b) || SegmentMeetsTriangle(besides(*a[v], p), p, b) ||
        SegmentMeetsTriangle(besides(*a[v], q), q, b))
      return true;
  }
  return false;
}

/** Triangles s and t share the edge from u to w; the third vertices are a and
 *  b. They overlap only when folded onto each other: (nearly) the same half-plane. */
bool
FoldedOver(const Vec3 & u, const Vec3 & w, const Vec3 & a, const Vec3 & b)
{
  const Vec3   e = Sub(w, u);
  const double ee = Dot(e, e);
  if (ee <= 0.0)
    return true;
  Vec3 pa = Sub(a, u), pb = Sub(b, u);
  const double fa = Dot(pa, e) / ee, fb = Dot(pb, e) / ee;
  for (int k = 0; k < 3; ++k)
  {
    pa[k] -= fa * e[k];
    pb[k] -= fb * e[k];
  }
  const double na = std::sqrt(Dot(pa, pa)), nb = std::sqrt(Dot(pb, pb));
  if (na <= 0.0 || nb <= 0.0)
    return true;
  return Dot(pa, pb) / (na * nb) > std::cos(0.5 * 3.14159265358979323846 / 180.0); // within half a degree
}

struct Box
{
  Vec3 lo, hi;
};

/** Pairs of intersecting triangles among `triangles` over `vertices`;
 *  `consider(i, j)` picks the pairs that count. */
template <typename TConsider>
std::size_t
CountMeetingPairs(const std::vector<Vec3> & vertices, const std::vector<std::array<std::uint32_t, 3>> & triangles,
                  TConsider consider)
{
  std::vector<Box> boxes(triangles.size());
  double           scale = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    Box & b = boxes[t];
    b.lo = b.hi = vertices[triangles[t][0]];
    for (int v = 1; v < 3; ++v)
      for (int k = 0; k < 3; ++k)
      {
        b.lo[k] = std::min(b.lo[k], vertices[triangles[t][v]][k]);
        b.hi[k] = std::max(b.hi[k], vertices[triangles[t][v]][k]);
      }
    for (int k = 0; k < 3; ++k)
      scale = std::max(scale, b.hi[k] - b.lo[k]);
  }
  const double slack = 1e-9 * scale;
  // Sweep along x: a triangle meets only those whose boxes overlap its own.
  std::vector<std::size_t> order(triangles.size());
  std::iota(order.begin(), order.end(), std::size_t{ 0 });
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return boxes[a].lo[0] < boxes[b].lo[0]; });
  std::size_t count = 0;
  for (std::size_t x = 0; x < order.size(); ++x)
  {
    const std::size_t i = order[x];
    for (std::size_t y = x + 1; y < order.size() && boxes[order[y]].lo[0] <= boxes[i].hi[0] + slack; ++y)
    {
      const std::size_t j = order[y];
      if (boxes[j].lo[1] > boxes[i].hi[1] + slack || boxes[i].lo[1] > boxes[j].hi[1] + slack ||
          boxes[j].lo[2] > boxes[i].hi[2] + slack || boxes[i].lo[2] > boxes[j].hi[2] + slack || !consider(i, j))
        continue;
      const auto &       a = triangles[i];
      const auto &       b = triangles[j];
      const Vec3 * const s[3] = { &vertices[a[0]], &vertices[a[1]], &vertices[a[2]] };
      const Vec3 * const t[3] = { &vertices[b[0]], &vertices[b[1]], &vertices[b[2]] };
      int                shared = 0, si[3] = { 0, 0, 0 }, ti[3] = { 0, 0, 0 };
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q)
          if (a[p] == b[q])
          {
            si[shared] = p;
            ti[shared] = q;
            ++shared;
          }
      bool meet = false;
      if (shared == 0)
        meet = TrianglesMeet(s, t);
      else if (shared == 1)
        meet = TrianglesMeetBesideVertex(s, si[0], t, ti[0]);
      else if (shared == 2)
        meet = FoldedOver(*s[si[0]], *s[si[1]], *s[3 - si[0] - si[1]], *t[3 - ti[0] - ti[1]]);
      else
        meet = true; // the same triangle twice
      count += meet;
    }
  }
  return count;
}

std::string
Plural(std::size_t n, const char * one, const char * many)
{
  return std::to_string(n) + " " + (n == 1 ? one : many);
}
} // namespace

std::string
SurfaceDefects::Describe() const
{
  std::string text;
  const auto  add = [&](std::size_t n, const char * one, const char * many) {
    if (n > 0)
      text += (text.empty() ? "" : ", ") + Plural(n, one, many);
  };
  add(openEdges, "open edge", "open edges");
  add(nonManifoldEdges, "edge of more than two triangles", "edges of more than two triangles");
  add(misorientedEdges, "inconsistently oriented edge", "inconsistently oriented edges");
  add(degenerateTriangles, "degenerate triangle", "degenerate triangles");
  add(duplicateVertices, "duplicate vertex", "duplicate vertices");
  add(crossingPairs, "pair of intersecting triangles", "pairs of intersecting triangles");
  return text;
}

SurfaceDefects
CheckSurface(const TriangleSurface & surface)
{
  SurfaceDefects d;
  const auto &   v = surface.vertices;
  // Edges: each undirected edge twice, once each way.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<int, 2>> edges; // (min, max) -> uses per direction
  for (const auto & t : surface.triangles)
    for (int e = 0; e < 3; ++e)
    {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      ++edges[{ std::min(a, b), std::max(a, b) }][a < b ? 0 : 1];
    }
  for (const auto & [edge, uses] : edges)
  {
    const int total = uses[0] + uses[1];
    d.openEdges += total == 1;
    d.nonManifoldEdges += total > 2;
    d.misorientedEdges += total == 2 && uses[0] != 1;
  }
  for (const auto & t : surface.triangles)
  {
    const Vec3   n = Cross(Sub(v[t[1]], v[t[0]]), Sub(v[t[2]], v[t[0]]));
    double       longest = 0.0;
    for (int e = 0; e < 3; ++e)
    {
      const Vec3 d2 = Sub(v[t[(e + 1) % 3]], v[t[e]]);
      longest = std::max(longest, Dot(d2, d2));
    }
    // Twice the area against the longest edge squared: about the smallest angle.
    d.degenerateTriangles += !(std::sqrt(Dot(n, n)) > 1e-6 * longest);
  }
  std::vector<Vec3> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 1; i < sorted.size(); ++i)
    d.duplicateVertices += sorted[i] == sorted[i - 1];
  d.crossingPairs = CountMeetingPairs(v, surface.triangles, [](std::size_t, std::size_t) { return true; });
  return d;
}

std::size_t
CountCrossings(const TriangleSurface & a, const TriangleSurface & b)
{
  TriangleSurface both = a;
  const auto      offset = static_cast<std::uint32_t>(a.vertices.size());
  both.vertices.insert(both.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto & t : b.triangles)
    both.triangles.push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
  const std::size_t first = a.triangles.size();
  return CountMeetingPairs(both.vertices, both.triangles,
                           [first](std::size_t i, std::size_t j) { return (i < first) != (j < first); });
}
} // namespace morea_core
