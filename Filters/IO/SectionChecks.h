/**
 * @file SectionChecks.h
 * @brief What readTurboPointSets does to the point sets before handing them on, so that
 * no template folds a grid on them: closing blade sections left open, span order, and
 * contours and sections that turn back or cross themselves. Plain C++17 + Eigen.
 *
 * Geometry is judged in the machine's own coordinates: the meridional plane (axial
 * position a, radius r about the axis through the origin) for hub and shroud contours,
 * and the blade-to-blade plane (meridional position along the section, r * theta) for
 * blade sections, so the checks hold for axial, mixed-flow and radial machines alike.
 */
#pragma once

#include "TurboPointSets.h"

#include <string>
#include <vector>

namespace blockforge
{
namespace io
{
/// Gaps (over the chord) up to which an open section is joined (rounding in the export)
/// and capped (a blunt trailing edge); larger gaps are left open (see closeSections).
constexpr double JoinLimit = 0.002;
constexpr double CapLimit = 0.05;

/**
 * Closes every section whose first and last points differ:
 * - gap <= JoinLimit * chord and below half the point spacing at the ends: both ends
 *   move to their midpoint (Closure::Joined);
 * - gap up to 1.5 point spacings: the file does not repeat its first point; it is
 *   repeated at the end (Closure::Segment);
 * - gap <= CapLimit * chord: a cap across the gap (`cap`: straight, or a half circle
 *   bulging along the sides' end tangents) with points about as far apart as the last
 *   ones of the sides, ending on the first point (Closure::Capped);
 * - larger gaps cannot be a trailing edge: the section is left open (the templates that
 *   need closed sections refuse it, with the measured gap).
 * The chord is the largest distance between two points of the section. Appends one
 * warning per kind of repair to `warnings`, with the gaps in % of the chord and in
 * `units`.
 */
void closeSections(std::vector<ProfileSection>& sections, EdgeCap cap, const std::string& file,
  const std::string& units, std::vector<std::string>& warnings);

/**
 * Puts the sections of each blade (by `## name`) in span order:
 * - sections whose headers all give spans are sorted by them (a warning gives the file
 *   order); two sections at the same span are an error;
 * - with a hub and a shroud, each section's place between them is measured (its
 *   centroid in the meridional plane, 0 at the hub, 1 at the shroud). Sections with
 *   guessed spans are sorted by it (and their spans guessed again in that order, with a
 *   warning); sections whose given spans disagree with it are an error naming them with
 *   the measured order.
 */
void orderSections(std::vector<ProfileSection>& sections, const PointSet& hub,
  const PointSet& shroud, const Eigen::Vector3d& axis, std::vector<std::string>& warnings);

/**
 * Refuses (ReadError naming the file and rows) a hub or shroud contour that turns back
 * (an angle above 120 degrees between consecutive segments in the meridional plane) or
 * crosses itself, and a blade section that crosses itself in the blade-to-blade plane or
 * turns back sharply (above 150 degrees) at more than two places (a leading and a
 * trailing edge).
 */
void checkContourShape(const PointSet& contour, const Eigen::Vector3d& axis);
void checkSectionShape(const ProfileSection& section, const Eigen::Vector3d& axis);
} // namespace io
} // namespace blockforge
