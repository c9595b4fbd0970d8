/**
 * @file TurboPointSets.cpp
 * @brief Reading of a whole turbomachinery point set: description files (.inf, Info.txt)
 * and their keys, the search for a set's point files by name and folder, the machine data
 * (blade count, axis, unit), and the checks of SectionChecks.h on the result.
 *
 * The point files themselves are parsed in PointFiles.cpp.
 */
#include "TurboPointSets.h"

#include "PointFiles.h"
#include "SectionChecks.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>
#include <system_error>

namespace fs = std::filesystem;

namespace blockforge
{
namespace io
{
using namespace parsing;

namespace
{
//------------------------------------------------------------------------------------------
// Description files (.inf, Info.txt)

struct Entry
{
  std::string key; // as written
  std::string value;
  int line = 0;
};

struct Description
{
  std::string path;
  std::map<std::string, Entry> entries; // by normalized key
};

/// Lower case, '.' and '_' removed, runs of blanks collapsed: "No. of  Blades" ->
/// "no of blades", so that exports differing in spelling details match.
std::string normalizeKey(const std::string& key)
{
  std::string result;
  bool blank = false;
  for (char c : key)
  {
    if (c == '.' || c == '_')
    {
      c = ' ';
    }
    if (isBlank(c))
    {
      blank = !result.empty();
      continue;
    }
    if (blank)
    {
      result += ' ';
      blank = false;
    }
    result += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return result;
}

const std::vector<std::string>& bladeCountKeys()
{
  static const std::vector<std::string> keys = { "number of blade sets", "number of blades",
    "no of blades", "nb of blades", "number of main blades", "blade count", "blades" };
  return keys;
}
const std::vector<std::string>& bladesPerSetKeys()
{
  static const std::vector<std::string> keys = { "number of blades per set", "blades per set" };
  return keys;
}
const std::vector<std::string>& axisKeys()
{
  static const std::vector<std::string> keys = { "axis of rotation", "rotation axis",
    "machine axis", "axis" };
  return keys;
}
const std::vector<std::string>& unitKeys()
{
  static const std::vector<std::string> keys = { "geometry units", "geometry unit",
    "coordinates unit", "coordinates units", "coordinate unit", "coordinate units", "units",
    "unit", "length units", "length unit" };
  return keys;
}

enum Role
{
  Hub = 0,
  Shroud = 1,
  Profile = 2,
  NoRole = 3
};

const char* roleLabel(int role)
{
  static const char* labels[] = { "hub", "shroud", "profile", "point" };
  return labels[role];
}

const std::vector<std::string>& fileKeys(int role)
{
  static const std::vector<std::vector<std::string>> keys = {
    { "hub data file", "hub file", "hub curve file", "hub" },
    { "shroud data file", "shroud file", "shroud curve file", "shroud", "casing data file",
      "casing file" },
    { "profile data file", "profile file", "profile curve file", "blade data file",
      "blade profile file", "profile" }
  };
  return keys[role];
}

bool isKnownKey(const std::string& normalized)
{
  for (const auto* list : { &bladeCountKeys(), &bladesPerSetKeys(), &axisKeys(), &unitKeys(),
         &fileKeys(Hub), &fileKeys(Shroud), &fileKeys(Profile) })
  {
    if (std::find(list->begin(), list->end(), normalized) != list->end())
    {
      return true;
    }
  }
  return false;
}

const Entry* findEntry(const Description& description, const std::vector<std::string>& keys)
{
  for (const auto& key : keys)
  {
    auto found = description.entries.find(key);
    if (found != description.entries.end() && !found->second.value.empty())
    {
      return &found->second;
    }
  }
  return nullptr;
}

/// @p strict (.inf): every line that is not blank or a comment must be "Key: value".
/// Otherwise (Info.txt, free notes) other lines are skipped.
Description readDescription(const std::string& path, bool strict)
{
  Description description;
  description.path = path;
  const std::vector<std::string> lines = readLines(path);
  for (std::size_t i = 0; i < lines.size(); ++i)
  {
    const int lineNumber = static_cast<int>(i) + 1;
    const std::string text = trim(lines[i]);
    if (text.empty() || text[0] == '!' || text[0] == '#')
    {
      continue;
    }
    const std::size_t colon = text.find(':');
    if (colon == std::string::npos || colon == 0)
    {
      if (strict)
      {
        throw ReadError(path, lineNumber, "expected 'Key: value', found '" + excerpt(text) + "'");
      }
      continue;
    }
    Entry entry;
    entry.key = trim(text.substr(0, colon));
    entry.value = trim(text.substr(colon + 1));
    if (entry.value.size() >= 2 &&
      ((entry.value.front() == '"' && entry.value.back() == '"') ||
        (entry.value.front() == '\'' && entry.value.back() == '\'')))
    {
      entry.value = trim(entry.value.substr(1, entry.value.size() - 2));
    }
    entry.line = lineNumber;
    description.entries[normalizeKey(entry.key)] = entry;
  }
  return description;
}

int parsePositiveInteger(const Entry& entry, const std::string& file, const std::string& what)
{
  int value = 0;
  const std::string& text = entry.value;
  const auto parsed = std::from_chars(text.data(), text.data() + text.size(), value);
  if (parsed.ec != std::errc() || parsed.ptr != text.data() + text.size() || value <= 0)
  {
    throw ReadError(file, entry.line,
      what + " '" + excerpt(text) + "' is not a positive whole number");
  }
  return value;
}

const char* const unitChoices = "expected M, CM, MM, IN or FT";

//------------------------------------------------------------------------------------------
// Files and folders

bool isRegularFile(const fs::path& path)
{
  std::error_code error;
  return fs::is_regular_file(path, error);
}

std::string extensionOf(const fs::path& path)
{
  return lower(path.extension().string());
}

bool isPointExtension(const std::string& extension)
{
  static const std::set<std::string> extensions = { ".dat", ".curve", ".crv", ".csv", ".txt",
    ".xyz", ".pts" };
  return extensions.count(extension) > 0;
}

std::vector<fs::path> filesIn(const fs::path& folder)
{
  std::vector<fs::path> files;
  std::error_code error;
  for (fs::directory_iterator it(folder.empty() ? fs::path(".") : folder, error), end;
       !error && it != end; it.increment(error))
  {
    if (isRegularFile(it->path()))
    {
      files.push_back(it->path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Role of a point file from its name: hub, shroud (or casing), profile (or blade).
int roleOf(const fs::path& path)
{
  const std::string name = lower(path.stem().string());
  if (name.find("hub") != std::string::npos)
  {
    return Hub;
  }
  if (name.find("shroud") != std::string::npos || name.find("casing") != std::string::npos)
  {
    return Shroud;
  }
  if (name.find("profile") != std::string::npos || name.find("blade") != std::string::npos)
  {
    return Profile;
  }
  return NoRole;
}

/// The file name without its role word ("profile_R37" -> "_r37"), to pair the files of
/// one set when a folder holds several.
std::string roleFreeStem(const fs::path& path)
{
  std::string name = lower(path.stem().string());
  for (const char* word : { "profile", "shroud", "casing", "blade", "hub" })
  {
    const std::size_t at = name.find(word);
    if (at != std::string::npos)
    {
      name.erase(at, std::string(word).size());
      break;
    }
  }
  return name;
}

/// Finds a file named in a description: as written relative to the description's
/// folder, with Windows separators, then by its bare name beside the description (exports
/// often carry the exporting machine's absolute paths), then ignoring case (written on a
/// case-insensitive file system).
std::optional<fs::path> locate(const fs::path& folder, const std::string& written)
{
  std::vector<fs::path> candidates;
  const fs::path asWritten(written);
  candidates.push_back(asWritten.is_absolute() ? asWritten : folder / asWritten);
  std::string slashed = written;
  std::replace(slashed.begin(), slashed.end(), '\\', '/');
  const fs::path withSlashes(slashed);
  candidates.push_back(withSlashes.is_absolute() ? withSlashes : folder / withSlashes);
  const fs::path bare = withSlashes.filename();
  candidates.push_back(folder / bare);
  for (const auto& candidate : candidates)
  {
    if (isRegularFile(candidate))
    {
      return candidate.lexically_normal();
    }
  }
  const std::string wanted = lower(bare.string());
  for (const auto& file : filesIn(folder))
  {
    if (lower(file.filename().string()) == wanted)
    {
      return file.lexically_normal();
    }
  }
  return std::nullopt;
}

bool sameFile(const fs::path& a, const fs::path& b)
{
  std::error_code error;
  const bool same = fs::equivalent(a, b, error);
  return !error && same;
}

/// First meaningful line is "Key: value" with a letter first: an Info.txt-like file.
bool looksLikeDescription(const std::vector<std::string>& lines)
{
  for (const auto& raw : lines)
  {
    const std::string text = trim(raw);
    if (text.empty() || text[0] == '!' || text[0] == '#')
    {
      continue;
    }
    const std::size_t colon = text.find(':');
    return colon != std::string::npos && colon > 0 &&
      std::isalpha(static_cast<unsigned char>(text[0]));
  }
  return false;
}

bool hasKnownKey(const std::vector<std::string>& lines)
{
  for (const auto& raw : lines)
  {
    const std::string text = trim(raw);
    const std::size_t colon = text.find(':');
    if (!text.empty() && text[0] != '!' && text[0] != '#' && colon != std::string::npos &&
      isKnownKey(normalizeKey(text.substr(0, colon))))
    {
      return true;
    }
  }
  return false;
}

PointSet toPointSet(ProfileSection&& section)
{
  PointSet result;
  result.name = std::move(section.name);
  result.points = std::move(section.points);
  result.file = std::move(section.file);
  result.firstLine = section.firstLine;
  result.lines = std::move(section.lines);
  return result;
}
} // namespace

//------------------------------------------------------------------------------------------
bool unitScale(const std::string& word, double& scale, std::string& canonical)
{
  std::string text = upper(trim(word));
  while (!text.empty() && text.back() == '.')
  {
    text.pop_back();
  }
  struct Unit
  {
    const char* name;
    double scale;
    std::vector<const char*> words;
  };
  static const std::vector<Unit> units = {
    { "M", 1.0, { "M", "METER", "METERS", "METRE", "METRES" } },
    { "CM", 0.01, { "CM", "CENTIMETER", "CENTIMETERS", "CENTIMETRE", "CENTIMETRES" } },
    { "MM", 0.001, { "MM", "MILLIMETER", "MILLIMETERS", "MILLIMETRE", "MILLIMETRES" } },
    { "IN", 0.0254, { "IN", "INCH", "INCHES" } },
    { "FT", 0.3048, { "FT", "FOOT", "FEET" } },
  };
  for (const auto& unit : units)
  {
    for (const char* candidate : unit.words)
    {
      if (text == candidate)
      {
        scale = unit.scale;
        canonical = unit.name;
        return true;
      }
    }
  }
  return false;
}

bool parseAxis(const std::string& text, Eigen::Vector3d& axis, std::string& name)
{
  std::string value = upper(trim(text));
  // "Z axis", "Z-axis", "Z_AXIS"
  const std::string tail = "AXIS";
  if (value.size() > tail.size() &&
    value.compare(value.size() - tail.size(), tail.size(), tail) == 0)
  {
    value = value.substr(0, value.size() - tail.size());
    while (!value.empty() &&
      (isBlank(value.back()) || value.back() == '-' || value.back() == '_'))
    {
      value.pop_back();
    }
  }
  std::string sign;
  std::string letter = value;
  if (!letter.empty() && (letter[0] == '-' || letter[0] == '+'))
  {
    sign = letter[0] == '-' ? "-" : "";
    letter = trim(letter.substr(1));
  }
  if (letter == "X" || letter == "Y" || letter == "Z")
  {
    axis = Eigen::Vector3d::Zero();
    axis[letter[0] - 'X'] = sign == "-" ? -1.0 : 1.0;
    name = sign + letter;
    return true;
  }
  // Three numbers, possibly in brackets.
  std::string numbers = value;
  for (char& c : numbers)
  {
    if (c == '(' || c == ')' || c == '[' || c == ']')
    {
      c = ' ';
    }
  }
  const std::vector<std::string> fields = splitFields(numbers);
  if (fields.size() != 3)
  {
    return false;
  }
  Eigen::Vector3d vector;
  for (int i = 0; i < 3; ++i)
  {
    if (!parseNumber(fields[i], vector[i]) || !std::isfinite(vector[i]))
    {
      return false;
    }
  }
  const double length = vector.norm();
  if (!(length > 0.0))
  {
    return false;
  }
  axis = vector / length;
  name = "(" + formatNumber(axis[0]) + ", " + formatNumber(axis[1]) + ", " +
    formatNumber(axis[2]) + ")";
  return true;
}

//------------------------------------------------------------------------------------------
TurboPointSets readTurboPointSets(
  const std::string& fileName, const ReadOptions& options, const ProgressCallback& progress)
{
  auto report = [&progress](double fraction) {
    if (progress)
    {
      progress(fraction);
    }
  };
  report(0.0);

  TurboPointSets sets;
  sets.sourceFile = fileName;

  const fs::path mainPath(fileName);
  const fs::path folder = fileName.empty() ? fs::path(".") : mainPath.parent_path();
  std::optional<Description> description;
  bool descriptionIsInf = false;
  // True when the user opened an Info.txt: its point files are found by their names.
  bool openedInfo = false;
  // Files for Hub, Shroud, Profile.
  std::optional<fs::path> files[3];
  // Explicit files replace all others, so no search is made for them.
  const std::string* overrides[3] = { &options.hubFile, &options.shroudFile,
    &options.profileFile };
  auto wanted = [&](int role) { return !files[role] && overrides[role]->empty(); };

  if (!fileName.empty())
  {
    if (!isRegularFile(mainPath))
    {
      throw ReadError(fileName, 0, "no such file");
    }
    const std::string extension = extensionOf(mainPath);
    const bool isInf = extension == ".inf";
    // Info.txt-like by name or by content ("Key: value" first), whatever the extension.
    const bool isInfo = !isInf &&
      (lower(mainPath.filename().string()) == "info.txt" ||
        looksLikeDescription(readLines(fileName, 4096)));
    if (isInf || isInfo)
    {
      description = readDescription(fileName, isInf);
      descriptionIsInf = isInf;
      openedInfo = !isInf;
    }
    else
    {
      // A point file: its role from its name, the rest of its set from beside it.
      const int role = roleOf(mainPath);
      files[role == NoRole ? Profile : role] = mainPath;
      for (const auto& file : filesIn(folder))
      {
        if (extensionOf(file) != ".inf")
        {
          continue;
        }
        try
        {
          Description candidate = readDescription(file.string(), true);
          for (int r = Hub; r <= Profile; ++r)
          {
            const Entry* entry = findEntry(candidate, fileKeys(r));
            if (entry)
            {
              const auto located = locate(folder, entry->value);
              if (located && sameFile(*located, mainPath))
              {
                description = candidate;
                descriptionIsInf = true;
              }
            }
          }
        }
        catch (const ReadError&)
        {
          // An unrelated or broken .inf beside the file: not ours to judge.
        }
        if (description)
        {
          files[Hub].reset();
          files[Shroud].reset();
          files[Profile].reset();
          break;
        }
      }
      if (!description)
      {
        for (const auto& file : filesIn(folder))
        {
          if (lower(file.filename().string()) == "info.txt")
          {
            description = readDescription(file.string(), false);
            break;
          }
        }
        // Siblings with the same extension and the same name apart from the role word
        // (hub_R37.dat for profile_R37.dat); else the only one with that role word.
        const std::string stem = roleFreeStem(mainPath);
        for (int r = Hub; r <= Profile; ++r)
        {
          if (!wanted(r))
          {
            continue;
          }
          std::vector<fs::path> exact;
          std::vector<fs::path> any;
          for (const auto& file : filesIn(folder))
          {
            if (extensionOf(file) != extension || roleOf(file) != r || sameFile(file, mainPath))
            {
              continue;
            }
            any.push_back(file);
            if (roleFreeStem(file) == stem)
            {
              exact.push_back(file);
            }
          }
          if (exact.size() == 1)
          {
            files[r] = exact.front();
          }
          else if (exact.empty() && any.size() == 1)
          {
            files[r] = any.front();
          }
          else if (!exact.empty() || !any.empty())
          {
            sets.warnings.push_back(std::string("several ") + roleLabel(r) +
              " files beside " + fileName + "; none used (choose one explicitly)");
          }
        }
      }
    }
  }
  report(0.05);

  // Files named by the description.
  if (description)
  {
    sets.descriptionFile = description->path;
    const fs::path descriptionFolder = fs::path(description->path).parent_path();
    for (int r = Hub; r <= Profile; ++r)
    {
      if (!wanted(r))
      {
        continue;
      }
      if (const Entry* entry = findEntry(*description, fileKeys(r)))
      {
        const auto located = locate(descriptionFolder, entry->value);
        if (!located)
        {
          throw ReadError(description->path, entry->line,
            entry->key + " '" + entry->value + "' not found (looked for " +
              (descriptionFolder / entry->value).lexically_normal().string() + ")");
        }
        files[r] = *located;
      }
    }
    // An Info.txt names no files: take the point files beside it by their names.
    if (openedInfo)
    {
      for (int r = Hub; r <= Profile; ++r)
      {
        if (!wanted(r))
        {
          continue;
        }
        std::vector<fs::path> candidates;
        for (const auto& file : filesIn(descriptionFolder))
        {
          if (isPointExtension(extensionOf(file)) && roleOf(file) == r &&
            !sameFile(file, description->path))
          {
            candidates.push_back(file);
          }
        }
        if (candidates.size() > 1)
        {
          std::string names;
          for (const auto& candidate : candidates)
          {
            names += (names.empty() ? "" : ", ") + candidate.filename().string();
          }
          throw ReadError(description->path, 0,
            std::string("several ") + roleLabel(r) + " files beside it (" + names +
              "); choose one explicitly");
        }
        if (candidates.size() == 1)
        {
          files[r] = candidates.front();
        }
      }
    }
    for (const auto& entry : description->entries)
    {
      sets.keys[entry.second.key] = entry.second.value;
    }
  }

  for (int r = Hub; r <= Profile; ++r)
  {
    if (overrides[r]->empty())
    {
      continue;
    }
    fs::path path(*overrides[r]);
    if (path.is_relative() && !fileName.empty())
    {
      path = folder / path;
    }
    if (!isRegularFile(path))
    {
      throw ReadError(*overrides[r], 0, std::string("cannot open the ") + roleLabel(r) + " file");
    }
    files[r] = path;
  }

  // Machine data: the description when it says, else the options.
  const std::string where =
    description ? description->path : (fileName.empty() ? std::string("(no file)") : fileName);
  bool bladeCountKnown = false;
  if (description)
  {
    if (const Entry* entry = findEntry(*description, bladeCountKeys()))
    {
      sets.bladeCount = parsePositiveInteger(*entry, description->path, "blade count");
      bladeCountKnown = true;
    }
    if (const Entry* entry = findEntry(*description, bladesPerSetKeys()))
    {
      sets.bladesPerSet = parsePositiveInteger(*entry, description->path, "blades per set");
    }
  }
  if (!bladeCountKnown)
  {
    if (options.bladeCount < 0)
    {
      throw ReadError(where, 0,
        "blade count " + std::to_string(options.bladeCount) + " is negative");
    }
    sets.bladeCount = options.bladeCount;
  }

  const Entry* axisEntry = description ? findEntry(*description, axisKeys()) : nullptr;
  if (axisEntry)
  {
    if (!parseAxis(axisEntry->value, sets.axis, sets.axisName))
    {
      throw ReadError(description->path, axisEntry->line,
        "unknown axis '" + excerpt(axisEntry->value) + "' (expected X, Y, Z or three numbers)");
    }
  }
  else if (!parseAxis(options.axis, sets.axis, sets.axisName))
  {
    throw ReadError(where, 0,
      "the files give no axis and the default axis '" + options.axis +
        "' is not one (expected X, Y, Z or three numbers)");
  }

  sets.bladeCountFromFiles = bladeCountKnown;
  sets.axisFromFiles = axisEntry != nullptr;
  const Entry* unitEntry = description ? findEntry(*description, unitKeys()) : nullptr;
  sets.unitsFromFiles = unitEntry != nullptr;
  if (unitEntry)
  {
    // "cm" or "cm (centimetres)": the whole value, else its first word.
    const std::vector<std::string> words = splitFields(unitEntry->value);
    if (!unitScale(unitEntry->value, sets.scale, sets.units) &&
      (words.empty() || !unitScale(words.front(), sets.scale, sets.units)))
    {
      throw ReadError(description->path, unitEntry->line,
        "unknown unit '" + excerpt(unitEntry->value) + "' (" + unitChoices + ")");
    }
  }
  else if (!unitScale(options.units, sets.scale, sets.units))
  {
    throw ReadError(where, 0,
      "the files give no unit and the default unit '" + options.units + "' is not one (" +
        unitChoices + ")");
  }
  report(0.1);

  // The point files.
  if (!files[Hub] && !files[Shroud] && !files[Profile])
  {
    throw ReadError(where, 0,
      "no point files: name them in the description file or choose them explicitly");
  }
  if (files[Hub])
  {
    sets.hub = toPointSet(std::move(readPointFile(files[Hub]->string(), false).front()));
    sets.hub.name = "Hub";
  }
  report(0.25);
  if (files[Shroud])
  {
    sets.shroud = toPointSet(std::move(readPointFile(files[Shroud]->string(), false).front()));
    sets.shroud.name = "Shroud";
  }
  report(0.4);
  if (files[Profile])
  {
    sets.profiles = readPointFile(files[Profile]->string(), true);
    // A lone section needs no span; several without one get guessed spans.
    if (sets.profiles.size() > 1 &&
      std::any_of(sets.profiles.begin(), sets.profiles.end(),
        [](const ProfileSection& s) { return !s.spanGiven; }))
    {
      sets.warnings.push_back(files[Profile]->string() +
        ": sections without '# Profile k at s%' headers; spans assumed evenly spread");
    }
  }
  // What would fold a grid: open sections, sections out of span order, contours and
  // sections that turn back or cross themselves.
  if (!sets.hub.points.empty())
  {
    checkContourShape(sets.hub, sets.axis);
  }
  if (!sets.shroud.points.empty())
  {
    checkContourShape(sets.shroud, sets.axis);
  }
  if (!sets.profiles.empty())
  {
    closeSections(
      sets.profiles, options.cap, files[Profile]->string(), sets.units, sets.warnings);
    orderSections(sets.profiles, sets.hub, sets.shroud, sets.axis, sets.warnings);
    for (const ProfileSection& section : sets.profiles)
    {
      checkSectionShape(section, sets.axis);
    }
  }
  if (descriptionIsInf)
  {
    for (int r = Hub; r <= Profile; ++r)
    {
      if (!files[r])
      {
        sets.warnings.push_back(
          sets.descriptionFile + ": names no " + roleLabel(r) + " file");
      }
    }
  }
  report(1.0);
  return sets;
}

//------------------------------------------------------------------------------------------
bool canReadTurboPointSets(const std::string& fileName)
{
  try
  {
    const fs::path path(fileName);
    if (fileName.empty() || !isRegularFile(path))
    {
      return false;
    }
    // Only the head of the file: this runs for every candidate file the user opens,
    // including large files of other formats sharing the extension.
    const std::vector<std::string> lines = readLines(fileName, 65536);
    const std::string extension = extensionOf(path);
    if (extension == ".inf" || lower(path.filename().string()) == "info.txt" ||
      looksLikeDescription(lines))
    {
      return hasKnownKey(lines);
    }
    int rows = 0;
    bool headerAllowed = true;
    // The last line may be cut by the byte limit.
    std::error_code error;
    const bool cut = fs::file_size(path, error) > 65536 && !error;
    const std::size_t usable = cut && !lines.empty() ? lines.size() - 1 : lines.size();
    for (std::size_t i = 0; i < usable && rows < 20; ++i)
    {
      const ClassifiedLine kind = classify(lines[i], fileName, static_cast<int>(i) + 1);
      if (kind.kind != LineKind::Data)
      {
        continue;
      }
      const std::vector<std::string> fields = splitFields(lines[i]);
      double value = 0.0;
      const bool numeric = fields.size() == 3 &&
        std::all_of(fields.begin(), fields.end(),
          [&value](const std::string& f) { return parseNumber(f, value) && std::isfinite(value); });
      if (numeric)
      {
        ++rows;
        headerAllowed = false;
        continue;
      }
      const bool anyNumber = std::any_of(fields.begin(), fields.end(),
        [&value](const std::string& f) { return parseNumber(f, value); });
      if (headerAllowed && !anyNumber)
      {
        headerAllowed = false;
        continue;
      }
      return false;
    }
    return rows > 0;
  }
  catch (...)
  {
    return false;
  }
}

} // namespace io
} // namespace blockforge
