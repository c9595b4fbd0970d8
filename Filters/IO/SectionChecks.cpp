#include "SectionChecks.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

namespace blockforge
{
namespace io
{
namespace
{
using Vector2 = Eigen::Vector2d;
using Vector3 = Eigen::Vector3d;
constexpr double Pi = 3.14159265358979323846;

/// Two unit vectors normal to the axis, for angles about it.
void radialFrame(const Vector3& axis, Vector3& e1, Vector3& e2)
{
  const Vector3 trial = std::abs(axis.x()) < 0.9 ? Vector3::UnitX() : Vector3::UnitY();
  e1 = (trial - trial.dot(axis) * axis).normalized();
  e2 = axis.cross(e1);
}

/// (axial position, radius) of a point about the axis through the origin.
Vector2 meridional(const Vector3& p, const Vector3& axis)
{
  const double a = p.dot(axis);
  return Vector2(a, (p - a * axis).norm());
}

std::vector<Vector2> meridional(const std::vector<Vector3>& points, const Vector3& axis)
{
  std::vector<Vector2> result;
  result.reserve(points.size());
  for (const Vector3& p : points)
  {
    result.push_back(meridional(p, axis));
  }
  return result;
}

double cross(const Vector2& a, const Vector2& b)
{
  return a.x() * b.y() - a.y() * b.x();
}

/// Blade-to-blade coordinates of a section: the position along the section's main
/// meridional direction, and r * (theta - theta of the centroid).
std::vector<Vector2> bladeToBlade(const std::vector<Vector3>& points, const Vector3& axis)
{
  Vector3 e1, e2;
  radialFrame(axis, e1, e2);
  const std::vector<Vector2> plane = meridional(points, axis);
  Vector2 mean = Vector2::Zero();
  Vector3 centroid = Vector3::Zero();
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    mean += plane[i];
    centroid += points[i];
  }
  mean /= static_cast<double>(points.size());
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (const Vector2& q : plane)
  {
    covariance += (q - mean) * (q - mean).transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
  const Vector2 along = solver.eigenvectors().col(1); // the larger eigenvalue
  const double theta0 = std::atan2(centroid.dot(e2), centroid.dot(e1));
  std::vector<Vector2> result;
  result.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    double theta = std::atan2(points[i].dot(e2), points[i].dot(e1)) - theta0;
    theta = std::remainder(theta, 2.0 * Pi);
    result.emplace_back(plane[i].dot(along), plane[i].y() * theta);
  }
  return result;
}

double chordOf(const std::vector<Vector3>& points)
{
  double longest2 = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    for (std::size_t j = i + 1; j < points.size(); ++j)
    {
      longest2 = std::max(longest2, (points[i] - points[j]).squaredNorm());
    }
  }
  return std::sqrt(longest2);
}

/// 3 significant digits: what a message needs of a measured length.
std::string threeDigits(double value)
{
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

std::string percent(double fraction)
{
  return threeDigits(100.0 * fraction) + " %";
}

/// "Profile 1 (0%), Profile 2 (25%), ... (12 in all)": at most `most` names.
std::string nameList(const std::vector<std::string>& names, std::size_t most = 4)
{
  std::string text;
  for (std::size_t i = 0; i < names.size() && i < most; ++i)
  {
    text += (i ? ", " : "") + names[i];
  }
  if (names.size() > most)
  {
    text += ", ... (" + std::to_string(names.size()) + " in all)";
  }
  return text;
}

/// Appends the cap points from the section's last point to its first (which is repeated
/// exactly as the new last point).
void addCap(ProfileSection& section, EdgeCap cap)
{
  std::vector<Vector3>& p = section.points;
  const std::size_t n = p.size();
  const Vector3 first = p.front(), last = p.back();
  const Vector3 gap = first - last;
  const double width = gap.norm();
  const double spacing = 0.5 * ((p[n - 1] - p[n - 2]).norm() + (p[1] - p[0]).norm());
  const double length = cap == EdgeCap::Rounded ? 0.5 * Pi * width : width;
  const int segments =
    static_cast<int>(std::clamp(std::round(length / std::max(spacing, 1e-300)), 1.0, 200.0));
  Vector3 outward = Vector3::Zero();
  if (cap == EdgeCap::Rounded)
  {
    // Along the sides' end tangents (both point past the edge), normal to the gap.
    const Vector3 unitGap = gap / width;
    outward = (p[n - 1] - p[n - 2]).normalized() + (p[0] - p[1]).normalized();
    outward -= outward.dot(unitGap) * unitGap;
    if (outward.norm() < 1e-6)
    {
      // Sides ending head-on: away from the section's centroid, in its surface.
      Vector3 centroid = Vector3::Zero();
      for (const Vector3& q : p)
      {
        centroid += q;
      }
      outward = 0.5 * (first + last) - centroid / static_cast<double>(n);
      outward -= outward.dot(unitGap) * unitGap;
    }
    outward.normalize();
  }
  const Vector3 middle = 0.5 * (first + last);
  const int line = section.lines.empty() ? section.firstLine : section.lines.back();
  for (int k = 1; k < segments; ++k)
  {
    const double f = static_cast<double>(k) / segments;
    if (cap == EdgeCap::Rounded)
    {
      const double phi = Pi * f;
      p.push_back(middle - 0.5 * std::cos(phi) * gap + 0.5 * width * std::sin(phi) * outward);
    }
    else
    {
      p.push_back(last + f * gap);
    }
    section.lines.push_back(line);
  }
  p.push_back(first);
  section.lines.push_back(line);
}

/// Where a point lies across the channel from a contour: the distance to the polyline in
/// the meridional plane, signed by the side.
double signedDistance(const std::vector<Vector2>& line, const Vector2& q)
{
  double best = std::numeric_limits<double>::infinity();
  double sign = 1.0;
  for (std::size_t i = 0; i + 1 < line.size(); ++i)
  {
    const Vector2 d = line[i + 1] - line[i];
    const double length2 = d.squaredNorm();
    const double t = length2 > 0.0 ? std::clamp((q - line[i]).dot(d) / length2, 0.0, 1.0) : 0.0;
    const double distance = (q - (line[i] + t * d)).norm();
    if (distance < best)
    {
      best = distance;
      sign = cross(d, q - line[i]) >= 0.0 ? 1.0 : -1.0;
    }
  }
  return sign * best;
}

/// The points without consecutive repeats, with the index of each kept point.
void distinct(const std::vector<Vector2>& points, std::vector<Vector2>& kept,
  std::vector<std::size_t>& index)
{
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    if (kept.empty() || points[i] != kept.back())
    {
      kept.push_back(points[i]);
      index.push_back(i);
    }
  }
}

/// Turning angle (degrees) at b between segments a-b and b-c.
double turn(const Vector2& a, const Vector2& b, const Vector2& c)
{
  const Vector2 d1 = b - a, d2 = c - b;
  const double cosine = std::clamp(d1.dot(d2) / (d1.norm() * d2.norm()), -1.0, 1.0);
  return std::acos(cosine) * 180.0 / Pi;
}

/// First pair of non-adjacent segments of the polyline (closed: also the segment from
/// the last point to the first) that cross each other properly; false when none.
bool findCrossing(const std::vector<Vector2>& q, bool closed, std::size_t& first,
  std::size_t& second)
{
  const std::size_t n = q.size();
  const std::size_t segments = closed ? n : n - 1;
  if (segments < 3)
  {
    return false;
  }
  auto end = [&](std::size_t s) { return q[(s + 1) % n]; };
  std::vector<std::size_t> order(segments);
  std::iota(order.begin(), order.end(), std::size_t(0));
  auto low = [&](std::size_t s) { return std::min(q[s].x(), end(s).x()); };
  auto high = [&](std::size_t s) { return std::max(q[s].x(), end(s).x()); };
  std::stable_sort(order.begin(), order.end(),
    [&](std::size_t a, std::size_t b) { return low(a) < low(b); });
  auto orient = [](const Vector2& a, const Vector2& b, const Vector2& c) {
    return cross(b - a, c - a);
  };
  bool found = false;
  for (std::size_t u = 0; u < segments; ++u)
  {
    const std::size_t s = order[u];
    for (std::size_t v = u + 1; v < segments && low(order[v]) <= high(s); ++v)
    {
      const std::size_t t = order[v];
      const std::size_t a = std::min(s, t), b = std::max(s, t);
      if (b == a + 1 || (closed && a == 0 && b == segments - 1))
      {
        continue; // neighbours share a point
      }
      if (std::max(q[a].y(), end(a).y()) < std::min(q[b].y(), end(b).y()) ||
        std::max(q[b].y(), end(b).y()) < std::min(q[a].y(), end(a).y()))
      {
        continue;
      }
      const double o1 = orient(q[a], end(a), q[b]), o2 = orient(q[a], end(a), end(b));
      const double o3 = orient(q[b], end(b), q[a]), o4 = orient(q[b], end(b), end(a));
      if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) &&
        ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
      {
        if (!found || a < first || (a == first && b < second))
        {
          first = a;
          second = b;
          found = true;
        }
      }
    }
  }
  return found;
}

int lineOf(const PointSet& set, std::size_t point)
{
  return point < set.lines.size() ? set.lines[point] : set.firstLine;
}
} // namespace

void closeSections(std::vector<ProfileSection>& sections, EdgeCap cap, const std::string& file,
  const std::string& units, std::vector<std::string>& warnings)
{
  struct Kind
  {
    std::vector<std::string> names;
    double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
    double smallestLength = std::numeric_limits<double>::infinity(), largestLength = 0.0;
    void add(const ProfileSection& section, double gap)
    {
      names.push_back(section.name);
      smallest = std::min(smallest, section.gapFraction);
      largest = std::max(largest, section.gapFraction);
      smallestLength = std::min(smallestLength, gap);
      largestLength = std::max(largestLength, gap);
    }
    /// "0.02 %" or "1.2 % to 1.5 %", and the same in the file's unit.
    std::string range(const std::string& units) const
    {
      const std::string low = percent(smallest), high = percent(largest);
      const std::string lowLength = threeDigits(smallestLength);
      const std::string highLength = threeDigits(largestLength);
      return (low == high ? low : low + " to " + high) + " of the chord (" +
        (lowLength == highLength ? lowLength : lowLength + " to " + highLength) + " " + units +
        ")";
    }
    std::string head(const std::string& file) const
    {
      return file + ": " + std::to_string(names.size()) + " section" +
        (names.size() == 1 ? " was" : "s were");
    }
  };
  Kind joined, linked, capped;
  for (ProfileSection& section : sections)
  {
    std::vector<Vector3>& p = section.points;
    const std::size_t n = p.size();
    if (n < 4 || p.front() == p.back())
    {
      continue;
    }
    const double gap = (p.front() - p.back()).norm();
    section.gapFraction = gap / chordOf(p);
    const double spacing = 0.5 * ((p[n - 1] - p[n - 2]).norm() + (p[1] - p[0]).norm());
    if (section.gapFraction <= 1e-9)
    {
      p.back() = p.front(); // round-off, below what any template tells apart
    }
    else if (section.gapFraction > CapLimit)
    {
      section.closure = Closure::Open;
    }
    else if (section.gapFraction <= JoinLimit && gap <= 0.5 * spacing)
    {
      const Vector3 middle = 0.5 * (p.front() + p.back());
      p.front() = middle;
      p.back() = middle;
      section.closure = Closure::Joined;
      joined.add(section, gap);
    }
    else if (gap <= 1.5 * spacing)
    {
      p.push_back(p.front());
      section.lines.push_back(section.lines.empty() ? section.firstLine : section.lines.back());
      section.closure = Closure::Segment;
      linked.add(section, gap);
    }
    else
    {
      addCap(section, cap);
      section.closure = Closure::Capped;
      capped.add(section, gap);
    }
  }
  if (!joined.names.empty())
  {
    warnings.push_back(joined.head(file) + " open by " + joined.range(units) +
      ", from rounding: their ends were joined (" + nameList(joined.names) + ")");
  }
  if (!linked.names.empty())
  {
    warnings.push_back(linked.head(file) + " open by about one point spacing (" +
      linked.range(units) + "): the first point was repeated at the end (" +
      nameList(linked.names) + ")");
  }
  if (!capped.names.empty())
  {
    warnings.push_back(capped.head(file) + " open at a blunt trailing edge of " +
      capped.range(units) + ": closed by a " +
      (cap == EdgeCap::Rounded ? "rounded" : "straight") + " cap (" + nameList(capped.names) +
      ")");
  }
}

void orderSections(std::vector<ProfileSection>& sections, const PointSet& hub,
  const PointSet& shroud, const Eigen::Vector3d& axis, std::vector<std::string>& warnings)
{
  // Blades in order of their first section; each keeps its sections together.
  std::vector<std::string> blades;
  std::map<std::string, std::vector<ProfileSection>> groups;
  for (ProfileSection& section : sections)
  {
    if (groups.find(section.blade) == groups.end())
    {
      blades.push_back(section.blade);
    }
    groups[section.blade].push_back(std::move(section));
  }
  const bool measurable = hub.points.size() >= 2 && shroud.points.size() >= 2;
  std::vector<Vector2> hubLine, shroudLine;
  double hubSide = 1.0, shroudSide = 1.0;
  if (measurable)
  {
    hubLine = meridional(hub.points, axis);
    shroudLine = meridional(shroud.points, axis);
    hubSide = signedDistance(hubLine, shroudLine[shroudLine.size() / 2]) >= 0 ? 1.0 : -1.0;
    shroudSide = signedDistance(shroudLine, hubLine[hubLine.size() / 2]) >= 0 ? 1.0 : -1.0;
  }
  sections.clear();
  for (const std::string& blade : blades)
  {
    std::vector<ProfileSection>& group = groups[blade];
    const std::string& file = group.front().file;
    const bool withBlade = blades.size() > 1;
    const bool allGiven = std::all_of(
      group.begin(), group.end(), [](const ProfileSection& s) { return s.spanGiven; });
    const bool noneGiven = std::none_of(
      group.begin(), group.end(), [](const ProfileSection& s) { return s.spanGiven; });
    auto fileOrder = [&group]() {
      std::vector<std::string> names;
      for (const ProfileSection& s : group)
      {
        names.push_back(s.name);
      }
      return nameList(names, 6);
    };
    if (allGiven && group.size() > 1)
    {
      std::vector<ProfileSection> sorted = group;
      std::stable_sort(sorted.begin(), sorted.end(),
        [](const ProfileSection& a, const ProfileSection& b) {
          return a.spanPercent < b.spanPercent;
        });
      for (std::size_t k = 0; k + 1 < sorted.size(); ++k)
      {
        if (sorted[k].spanPercent == sorted[k + 1].spanPercent)
        {
          throw ReadError(file, sorted[k + 1].firstLine,
            "section '" + sorted[k + 1].name + "' is at the same span as section '" +
              sorted[k].name + "' (line " + std::to_string(sorted[k].firstLine) +
              "): every section needs its own span");
        }
      }
      if (sorted.front().firstLine != group.front().firstLine ||
        !std::equal(sorted.begin(), sorted.end(), group.begin(),
          [](const ProfileSection& a, const ProfileSection& b) {
            return a.firstLine == b.firstLine;
          }))
      {
        warnings.push_back(file + ": sections sorted by the spans of their headers (file order: " +
          fileOrder() + ")");
        group = std::move(sorted);
      }
    }
    if (measurable && group.size() > 1 && (allGiven || noneGiven))
    {
      std::vector<double> measured;
      for (const ProfileSection& section : group)
      {
        Vector2 centroid = Vector2::Zero();
        for (const Vector3& p : section.points)
        {
          centroid += meridional(p, axis);
        }
        centroid /= static_cast<double>(section.points.size());
        const double fromHub = hubSide * signedDistance(hubLine, centroid);
        const double fromShroud = shroudSide * signedDistance(shroudLine, centroid);
        measured.push_back(fromHub / (fromHub + fromShroud));
      }
      const bool increasing = std::is_sorted(measured.begin(), measured.end(),
                                std::less_equal<double>()) &&
        std::adjacent_find(measured.begin(), measured.end()) == measured.end();
      if (!increasing)
      {
        std::vector<std::size_t> order(group.size());
        std::iota(order.begin(), order.end(), std::size_t(0));
        std::stable_sort(order.begin(), order.end(),
          [&measured](std::size_t a, std::size_t b) { return measured[a] < measured[b]; });
        std::string measuredOrder;
        for (std::size_t k : order)
        {
          measuredOrder += (measuredOrder.empty() ? "" : ", ") + group[k].name + " at " +
            percent(measured[k]);
        }
        if (allGiven)
        {
          std::size_t k = 0;
          while (measured[k + 1] > measured[k])
          {
            ++k;
          }
          throw ReadError(file, group[k + 1].firstLine,
            "section '" + group[k + 1].name + "' lies at " + percent(measured[k + 1]) +
              " of the span measured between hub and shroud, not beyond section '" +
              group[k].name + "' (line " + std::to_string(group[k].firstLine) + ") at " +
              percent(measured[k]) +
              ": the spans of the headers do not follow the sections from hub to shroud "
              "(measured order: " + measuredOrder + ")");
        }
        std::vector<ProfileSection> sorted;
        for (std::size_t k : order)
        {
          sorted.push_back(std::move(group[k]));
        }
        warnings.push_back(file + ": sections without spans were not in order from hub to "
                                  "shroud; sorted by where they lie (" + measuredOrder + ")");
        group = std::move(sorted);
        for (std::size_t k = 0; k < group.size(); ++k)
        {
          group[k].spanPercent = 100.0 * static_cast<double>(k) / (group.size() - 1);
          group[k].name = profileSectionName(group[k], withBlade);
        }
      }
    }
    for (ProfileSection& section : group)
    {
      sections.push_back(std::move(section));
    }
  }
}

void checkContourShape(const PointSet& contour, const Eigen::Vector3d& axis)
{
  std::vector<Vector2> q;
  std::vector<std::size_t> index;
  distinct(meridional(contour.points, axis), q, index);
  const std::string what = "the " + contour.name + " contour";
  for (std::size_t k = 1; k + 1 < q.size(); ++k)
  {
    const double angle = turn(q[k - 1], q[k], q[k + 1]);
    if (angle > 120.0)
    {
      std::ostringstream reason;
      reason.precision(3);
      reason << what << " turns back at this row: by " << angle << " degrees between lines "
             << lineOf(contour, index[k - 1]) << " and " << lineOf(contour, index[k + 1])
             << " (in the meridional plane); a contour must run one way (rows out of order?)";
      throw ReadError(contour.file, lineOf(contour, index[k]), reason.str());
    }
  }
  std::size_t a = 0, b = 0;
  if (findCrossing(q, false, a, b))
  {
    throw ReadError(contour.file, lineOf(contour, index[b]),
      what + " crosses itself: the segment between lines " +
        std::to_string(lineOf(contour, index[a])) + " and " +
        std::to_string(lineOf(contour, index[a + 1])) + " crosses the one between lines " +
        std::to_string(lineOf(contour, index[b])) + " and " +
        std::to_string(lineOf(contour, index[b + 1])) + " (in the meridional plane)");
  }
}

void checkSectionShape(const ProfileSection& section, const Eigen::Vector3d& axis)
{
  std::vector<Vector2> q;
  std::vector<std::size_t> index;
  distinct(bladeToBlade(section.points, axis), q, index);
  const bool closed = q.size() > 3 && q.front() == q.back();
  if (closed)
  {
    q.pop_back();
    index.pop_back();
  }
  const std::size_t n = q.size();
  if (n < 3)
  {
    return;
  }
  const std::string what = "section '" + section.name + "'";
  std::vector<std::size_t> sharp;
  for (std::size_t k = closed ? 0 : 1; k < (closed ? n : n - 1); ++k)
  {
    if (turn(q[(k + n - 1) % n], q[k], q[(k + 1) % n]) > 150.0)
    {
      sharp.push_back(k);
    }
  }
  if (sharp.size() > 2)
  {
    std::string lines;
    for (std::size_t k : sharp)
    {
      lines += (lines.empty() ? "" : ", ") + std::to_string(lineOf(section, index[k]));
    }
    throw ReadError(section.file, lineOf(section, index[sharp[0]]),
      what + " turns back sharply (by more than 150 degrees) at " +
        std::to_string(sharp.size()) + " rows (lines " + lines +
        "), more than a leading and a trailing edge: rows out of order or kinked?");
  }
  std::size_t a = 0, b = 0;
  if (findCrossing(q, closed, a, b))
  {
    throw ReadError(section.file, lineOf(section, index[b]),
      what + " crosses itself: the segment between lines " +
        std::to_string(lineOf(section, index[a])) + " and " +
        std::to_string(lineOf(section, index[(a + 1) % n])) +
        " crosses the one between lines " + std::to_string(lineOf(section, index[b])) +
        " and " + std::to_string(lineOf(section, index[(b + 1) % n])) +
        " (in the blade-to-blade plane); rows out of order?");
  }
}
} // namespace io
} // namespace blockforge
