/**
 * @file TurboPointSets.h
 * @brief Reading of turbomachinery point sets (hub, shroud, blade profiles): plain C++17 +
 *        Eigen, no VTK, so that it can be unit-tested on its own (Testing/Cxx).
 *
 * Two layouts are understood, both as they come from real exports:
 *
 * - TurboGrid / BladeGen: a description file `BladeGen.inf` with `Key: value` lines
 *   (`Axis of Rotation`, `Number of Blade Sets`, `Geometry Units`, `Hub Data File`,
 *   `Shroud Data File`, `Profile Data File`, ...) and `.curve`/`.crv` point files.
 * - Multi-section point files (`.dat`, `.csv`, `.txt`) such as the NASA Rotor 37 set, with
 *   the machine data in an `Info.txt` beside them (`No of blades`, `Axis of rotation`,
 *   `Coordinates unit`).
 *
 * Point files hold one point per row, X Y Z separated by blanks, tabs, commas or
 * semicolons; CRLF, lone CR and LF line ends and a UTF-8 byte order mark are accepted.
 * Lines starting with `!` or `#` are comments; `## name` names the blade of the sections
 * that follow. In a profile file every comment or blank line between two point rows
 * starts a new section, whatever its text (exports head sections with `# Profile 3 at
 * 16.6667%`, `# IGV Profile 1`, `# Rotor1 Profile 2`, or nothing but a blank line); a
 * comment with the words `Profile k` (or `Section k`) numbers the section, and `at s%`
 * after them gives its span. One leading row of column names (`x,y,z`) is skipped.
 *
 * readTurboPointSets then repairs and checks what would fold a grid (SectionChecks.h):
 * blade sections left open are closed (a gap up to 0.2 % of the chord joined, up to 5 %
 * capped as a blunt trailing edge, larger ones left open for the template to refuse),
 * sections are put in span order (by the spans of their headers, or where they lie
 * between hub and shroud) or refused when the headers contradict the geometry, and
 * contours and sections that turn back on themselves or cross themselves are refused,
 * naming the rows.

 * Coordinates are kept exactly as in the files; TurboPointSets::scale converts them to
 * metres (the VTK reader applies it).
 *
 * Errors are ReadError exceptions whose message is "file:line: what".
 */
#pragma once

#include <Eigen/Core>

#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace blockforge
{
namespace io
{

/// Raised for any problem in the input files. what() is "file:line: reason" (or
/// "file: reason" when no line applies) so that a user can go straight to the spot.
class ReadError : public std::runtime_error
{
public:
  ReadError(const std::string& file, int line, const std::string& reason);

  const std::string& file() const noexcept { return this->File; }
  /// 1-based line number, 0 when the problem concerns the whole file.
  int line() const noexcept { return this->Line; }
  const std::string& reason() const noexcept { return this->Reason; }

private:
  std::string File;
  int Line;
  std::string Reason;
};

/// One curve of points as read from a file (coordinates in the file's unit).
struct PointSet
{
  std::string name;
  std::vector<Eigen::Vector3d> points;
  std::string file; ///< path the points were read from
  int firstLine = 0; ///< line of the first point (or of the section header), 1-based
  /// Line of each point (1-based; points added to close a section carry the line of the
  /// section's last point), so that messages can name the rows.
  std::vector<int> lines;
};

/// How an open blade section was closed (see closeSections).
enum class Closure
{
  Closed, ///< the file's section was already a closed loop
  Open,   ///< a gap above 5 % of the chord, not a trailing edge: left as it is
  Joined, ///< a small gap (rounding) closed by moving both ends to their midpoint
  Segment, ///< the first point not repeated at the end (a gap of about one point
           ///< spacing): closed by repeating it
  Capped  ///< a blunt trailing edge closed by a cap (ReadOptions::cap)
};

/// Shape of the cap that closes a blunt trailing edge.
enum class EdgeCap
{
  Straight, ///< points along the straight line between the two ends (default)
  Rounded   ///< a half circle across the gap, bulging along the sides' end tangents
};

/// One blade section of the profile file.
struct ProfileSection : PointSet
{
  int number = 0; ///< k of `# Profile k at s%`, else the 1-based position in the file
  double spanPercent = std::numeric_limits<double>::quiet_NaN();
  /// False when the file gives no span: spanPercent then spreads the sections evenly
  /// from 0 to 100 % in file order (a guess, recorded as such).
  bool spanGiven = false;
  std::string blade; ///< the `## name` in effect, empty if none
  Closure closure = Closure::Closed;
  /// Distance between the file's first and last point over the chord (largest distance
  /// between two points of the section), before closing.
  double gapFraction = 0.0;
};

/// Everything a blade-passage template needs from the input files.
struct TurboPointSets
{
  PointSet hub;    ///< meridional hub contour (empty when no hub file was found)
  PointSet shroud; ///< meridional shroud contour (empty when no shroud file was found)
  std::vector<ProfileSection> profiles;

  int bladeCount = 0;   ///< blade sets around the machine (rotational periodicity); 0 unknown
  int bladesPerSet = 1; ///< blades per set (main blade + splitters)
  Eigen::Vector3d axis{ 0.0, 0.0, 1.0 }; ///< unit vector of the machine axis
  std::string axisName = "Z";            ///< "X", "-Y", ... or "(ax, ay, az)"
  std::string units = "M";               ///< canonical unit of the files: M, CM, MM, IN, FT
  double scale = 1.0;                    ///< metres per file unit
  /// Whether the files gave the blade count, axis and unit (false: ReadOptions' value).
  bool bladeCountFromFiles = false, axisFromFiles = false, unitsFromFiles = false;

  /// The file given to readTurboPointSets and the description file used (.inf or
  /// Info.txt, empty if none), for provenance.
  std::string sourceFile;
  std::string descriptionFile;
  /// Every `Key: value` of the description file, keys as written (extra keys included).
  std::map<std::string, std::string> keys;
  /// Non-fatal remarks (guessed spans, missing parts, ...) for the caller to show.
  std::vector<std::string> warnings;
};

/// Values used when the files do not say, and explicit point files.
struct ReadOptions
{
  /// Point files that replace those named by (or found beside) the main file; a relative
  /// path is taken relative to the main file's folder. Empty: not overridden.
  std::string hubFile;
  std::string shroudFile;
  std::string profileFile;
  /// Used only when neither the main file nor a description file beside it says.
  int bladeCount = 0; ///< 0: unknown
  std::string axis = "Z";
  std::string units = "M";
  /// Cap that closes a blunt trailing edge (a gap between 0.2 % and 5 % of the chord).
  EdgeCap cap = EdgeCap::Straight;
};

/// Reports progress in [0, 1].
using ProgressCallback = std::function<void(double)>;

/**
 * Reads a complete set. @p fileName may be
 * - a `.inf` description file: its keys name the point files (relative to the .inf) and
 *   the machine data;
 * - an `Info.txt` (any file whose first meaningful line is `Key: value`): machine data,
 *   and point files named in it or found beside it by name (`*hub*`, `*shroud*` or
 *   `*casing*`, `*profile*` or `*blade*`);
 * - a single point file: its role comes from its name as above (a name that says
 *   neither is read as the profile file); a `.inf` beside it that names it, or else an
 *   `Info.txt` beside it, provides the machine data and the other point files, and
 *   point files beside it with the same extension and the same name apart from the role
 *   word (hub_R37.dat, shroud_R37.dat for profile_R37.dat) complete the set;
 * - empty, when @p options names the point files.
 * @throws ReadError on any error (unreadable or missing file, malformed row, value that
 *         is not a finite number, section with fewer than 4 points, unknown unit or axis,
 *         bad blade count, no points at all).
 */
TurboPointSets readTurboPointSets(const std::string& fileName, const ReadOptions& options = {},
  const ProgressCallback& progress = {});

/**
 * Reads one point file. With @p sections false all points form one curve (hub, shroud)
 * and a section header is an error; with @p sections true the file is split into
 * sections (see the file comment). Every section must have at least 4 points.
 */
std::vector<ProfileSection> readPointFile(const std::string& path, bool sections);

/// "Profile k (s%)", prefixed by "blade: " when @p withBlade and the section has one.
std::string profileSectionName(const ProfileSection& section, bool withBlade);

/// A number in the short form messages use ("0.05", "1.5e-07").
std::string formatNumber(double value);

/// Metres per unit for M, CM, MM, IN, FT (any case; also METRE(S), METER(S), INCH(ES),
/// FOOT, FEET, MILLIMETRE(S), ...). Sets @p canonical to the short upper-case name.
/// Returns false for an unknown word.
bool unitScale(const std::string& word, double& scale, std::string& canonical);

/// Parses an axis: X, Y, Z with an optional sign (also "X axis", "Z-axis"), or three
/// numbers. Returns false when it is neither or the vector is zero.
bool parseAxis(const std::string& text, Eigen::Vector3d& axis, std::string& name);

/// Cheap check, for reader selection, that @p fileName looks like one of the inputs above
/// (a description file with a known key, or a file whose first rows are X Y Z numbers or
/// section headers). Never throws.
bool canReadTurboPointSets(const std::string& fileName);

} // namespace io
} // namespace blockforge
