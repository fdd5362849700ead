// Copyright 2026 The MultiObjectiveRegistration authors
// SPDX-License-Identifier: Apache-2.0
#include "itkLandmarkIO.h"
#include "itkMOREAFail.h"

#include "itkMOREAImageIO.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace itk
{
namespace morea
{
namespace
{
std::string
Lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string
Trim(const std::string & s)
{
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos)
    return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

bool
ParseDouble(const std::string & text, double & value)
{
  const std::string t = Trim(text);
  if (t.empty())
    return false;
  char * end = nullptr;
  value = std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size() && std::isfinite(value);
}

LandmarkListType
ReadElastix(std::istream & in, const std::string & path, const std::string & kind,
            const ImageBase<Dimension> * reference)
{
  const bool isIndex = kind == "index";
  if (isIndex && reference == nullptr)
  {
    Fail("landmark file '" + path + "' holds voxel indices; the image they refer to is needed to read it");
  }
  long count = -1;
  if (!(in >> count) || count <= 0)
  {
    Fail("landmark file '" + path + "': expected a positive point count after '" + kind + "'");
  }
  LandmarkListType points;
  for (long n = 0; n < count; ++n)
  {
    double c[3];
    for (double & v : c)
    {
      std::string token;
      if (!(in >> token) || !ParseDouble(token, v))
      {
        Fail("landmark file '" + path + "': point " + std::to_string(n + 1) + " of " + std::to_string(count) +
             " is missing or not numeric");
      }
    }
    PointType p;
    if (isIndex)
    {
      ContinuousIndex<double, Dimension> index;
      for (unsigned d = 0; d < Dimension; ++d)
        index[d] = c[d];
      reference->TransformContinuousIndexToPhysicalPoint(index, p);
    }
    else
    {
      for (unsigned d = 0; d < Dimension; ++d)
        p[d] = c[d];
    }
    points.push_back(p);
  }
  std::string extra;
  if (in >> extra)
  {
    Fail("landmark file '" + path + "' has more values than its count of " + std::to_string(count) + " points");
  }
  return points;
}

std::vector<std::string>
SplitCsv(const std::string & line)
{
  std::vector<std::string> fields;
  std::stringstream        ss(line);
  std::string              f;
  while (std::getline(ss, f, ','))
    fields.push_back(Trim(f));
  return fields;
}

LandmarkListType
ReadCsv(std::istream & in, const std::string & path)
{
  LandmarkListType points;
  std::string      line;
  int              lineNumber = 0;
  int              column[3] = { -1, -1, -1 };
  bool             headerSeen = false;
  while (std::getline(in, line))
  {
    ++lineNumber;
    if (Trim(line).empty() || Trim(line)[0] == '#')
      continue;
    const auto fields = SplitCsv(line);
    double     probe = 0.0;
    if (!headerSeen && points.empty() && !fields.empty() && !ParseDouble(fields.back(), probe))
    {
      headerSeen = true;
      for (std::size_t i = 0; i < fields.size(); ++i)
      {
        const std::string name = Lower(fields[i]);
        for (int d = 0; d < 3; ++d)
          if (name == std::string(1, "xyz"[d]) || name == std::string(1, "xyz"[d]) + "_mm")
            column[d] = static_cast<int>(i);
      }
      if (column[0] < 0 || column[1] < 0 || column[2] < 0)
        Fail("landmark CSV '" + path + "': the header must name columns x, y and z");
      continue;
    }
    if (column[0] < 0)
    {
      if (fields.size() != 3)
        Fail("landmark CSV '" + path + "' line " + std::to_string(lineNumber) +
             ": expected 3 values x,y,z (or a header naming the x, y, z columns)");
      column[0] = 0;
      column[1] = 1;
      column[2] = 2;
    }
    PointType p;
    for (int d = 0; d < 3; ++d)
    {
      if (column[d] >= static_cast<int>(fields.size()) || !ParseDouble(fields[column[d]], p[d]))
        Fail("landmark CSV '" + path + "' line " + std::to_string(lineNumber) + ": coordinate " +
             std::string(1, "xyz"[d]) + " is missing or not numeric");
    }
    points.push_back(p);
  }
  if (points.empty())
    Fail("landmark CSV '" + path + "' holds no points");
  return points;
}

} // namespace

LandmarkListType
ReadLandmarks(const std::string & path, const ImageBase<Dimension> * reference)
{
  std::ifstream in(path);
  if (!in)
    Fail("cannot open landmark file '" + path + "'");
  std::string first;
  in >> first;
  const std::string kind = Lower(first);
  if (kind == "point" || kind == "index")
    return ReadElastix(in, path, kind, reference);
  in.clear();
  in.seekg(0);
  if (Lower(fs::path(path).extension().string()) == ".csv" || first.find(',') != std::string::npos)
    return ReadCsv(in, path);
  Fail("landmark file '" + path + "' is neither an elastix point file ('point' or 'index' first) nor CSV");
}

void
WriteElastixPointFile(const LandmarkListType & points, const std::string & path)
{
  std::ostringstream os;
  os.precision(10);
  os << "point\n" << points.size() << "\n";
  for (const auto & p : points)
    os << p[0] << " " << p[1] << " " << p[2] << "\n";
  WriteTextFile(os.str(), path);
}

void
WriteLandmarksCsv(const LandmarkListType & points, const std::string & path)
{
  std::ostringstream os;
  os.precision(10);
  os << "x,y,z\n";
  for (const auto & p : points)
    os << p[0] << "," << p[1] << "," << p[2] << "\n";
  WriteTextFile(os.str(), path);
}

} // namespace morea
} // namespace itk
