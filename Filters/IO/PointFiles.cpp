/**
 * @file PointFiles.cpp
 * @brief Parsing of the point files (hub and shroud contours, blade sections) and the text
 * layer beneath it (PointFiles.h), with the reader's error type.
 *
 * Split from TurboPointSets.cpp, which keeps the description files (.inf, Info.txt), the
 * search for a set's files and the machine data, and assembles the whole set.
 */
#include "PointFiles.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

namespace blockforge
{
namespace io
{
using namespace parsing;

namespace
{
std::string formatMessage(const std::string& file, int line, const std::string& reason)
{
  std::ostringstream message;
  message << file;
  if (line > 0)
  {
    message << ":" << line;
  }
  message << ": " << reason;
  return message.str();
}
} // namespace

ReadError::ReadError(const std::string& file, int line, const std::string& reason)
  : std::runtime_error(formatMessage(file, line, reason))
  , File(file)
  , Line(line)
  , Reason(reason)
{
}

namespace parsing
{
//------------------------------------------------------------------------------------------
// Text helpers

bool isBlank(char c)
{
  return c == ' ' || c == '\t' || c == '\v' || c == '\f';
}

std::string trim(const std::string& text)
{
  std::size_t begin = 0;
  std::size_t end = text.size();
  while (begin < end && isBlank(text[begin]))
  {
    ++begin;
  }
  while (end > begin && isBlank(text[end - 1]))
  {
    --end;
  }
  return text.substr(begin, end - begin);
}

std::string lower(std::string text)
{
  std::transform(text.begin(), text.end(), text.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string upper(std::string text)
{
  std::transform(text.begin(), text.end(), text.begin(),
    [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return text;
}

/// Splits at blanks, tabs, commas and semicolons (CSV and whitespace files alike).
std::vector<std::string> splitFields(const std::string& text)
{
  std::vector<std::string> fields;
  std::string current;
  for (char c : text)
  {
    if (isBlank(c) || c == ',' || c == ';')
    {
      if (!current.empty())
      {
        fields.push_back(current);
        current.clear();
      }
    }
    else
    {
      current += c;
    }
  }
  if (!current.empty())
  {
    fields.push_back(current);
  }
  return fields;
}

/// Short, printable excerpt of a row for error messages.
std::string excerpt(const std::string& text)
{
  std::string shown = trim(text);
  std::replace(shown.begin(), shown.end(), '\t', ' ');
  if (shown.size() > 60)
  {
    shown = shown.substr(0, 57) + "...";
  }
  return shown;
}

/// Parses a whole token as a number; locale-independent (ParaView may run with a
/// decimal-comma locale), accepts a leading '+' and Fortran's D exponent.
/// Returns false if the token is not a number; NaN and infinities parse (callers reject
/// them with a specific message).
bool parseNumber(const std::string& token, double& value)
{
  std::string text = token;
  if (!text.empty() && text[0] == '+')
  {
    text.erase(0, 1);
  }
  for (char& c : text)
  {
    if (c == 'd' || c == 'D')
    {
      c = 'e';
    }
  }
  if (text.empty())
  {
    return false;
  }
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(begin, end, value);
  return result.ec == std::errc() && result.ptr == end;
}

std::vector<std::string> readLines(const std::string& path, std::size_t maxBytes)
{
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    throw ReadError(path, 0, "cannot open the file");
  }
  std::string content;
  if (maxBytes > 0)
  {
    content.resize(maxBytes);
    stream.read(&content[0], static_cast<std::streamsize>(maxBytes));
    content.resize(static_cast<std::size_t>(stream.gcount()));
  }
  else
  {
    std::ostringstream buffer;
    buffer << stream.rdbuf();
    content = buffer.str();
  }
  if (content.compare(0, 3, "\xEF\xBB\xBF") == 0)
  {
    content.erase(0, 3);
  }
  std::vector<std::string> lines;
  std::string current;
  for (std::size_t i = 0; i < content.size(); ++i)
  {
    const char c = content[i];
    if (c == '\n' || c == '\r')
    {
      lines.push_back(current);
      current.clear();
      if (c == '\r' && i + 1 < content.size() && content[i + 1] == '\n')
      {
        ++i;
      }
    }
    else
    {
      current += c;
    }
  }
  if (!current.empty())
  {
    lines.push_back(current);
  }
  return lines;
}

//------------------------------------------------------------------------------------------
// Point files

ClassifiedLine classify(const std::string& raw, const std::string& file, int lineNumber)
{
  ClassifiedLine result;
  const std::string text = trim(raw);
  if (text.empty())
  {
    return result;
  }
  if (text[0] == '!')
  {
    result.kind = LineKind::Comment;
    return result;
  }
  if (text.compare(0, 2, "##") == 0)
  {
    result.kind = LineKind::Title;
    const std::size_t start = text.find_first_not_of('#');
    result.title = start == std::string::npos ? std::string() : trim(text.substr(start));
    return result;
  }
  if (text[0] == '#')
  {
    result.kind = LineKind::Comment;
    std::istringstream words(text.substr(1));
    std::vector<std::string> tokens;
    for (std::string word; words >> word;)
    {
      tokens.push_back(word);
    }
    std::size_t keywordAt = tokens.size();
    int number = 0;
    for (std::size_t t = 0; t + 1 < tokens.size() && keywordAt == tokens.size(); ++t)
    {
      const std::string keyword = lower(tokens[t]);
      const std::string& digits = tokens[t + 1];
      const auto parsed = std::from_chars(digits.data(), digits.data() + digits.size(), number);
      if ((keyword == "profile" || keyword == "section") && parsed.ec == std::errc() &&
        parsed.ptr == digits.data() + digits.size())
      {
        keywordAt = t;
      }
    }
    if (keywordAt == tokens.size())
    {
      return result;
    }
    result.kind = LineKind::Section;
    result.number = number;
    std::size_t next = keywordAt + 2;
    if (next == tokens.size())
    {
      return result;
    }
    // The span: the first number after the keyword that follows "at" or carries a "%"
    // ("at 16.6667%", "at 12.5 %", "at span 50", "50% span").
    const bool at = lower(tokens[next]) == "at";
    double span = 0.0;
    bool found = false;
    for (std::size_t i = next; i < tokens.size() && !found; ++i)
    {
      std::string word = tokens[i];
      const bool percent = !word.empty() && word.back() == '%';
      if (percent)
      {
        word.pop_back();
      }
      const bool percentNext = i + 1 < tokens.size() && tokens[i + 1] == "%";
      found = !word.empty() && parseNumber(word, span) && (at || percent || percentNext);
    }
    if (!found)
    {
      if (!at)
      {
        return result; // more words after "Profile k", but no span
      }
      throw ReadError(file, lineNumber,
        "malformed section header '" + excerpt(text) + "' (expected '# Profile k at s%')");
    }
    if (!std::isfinite(span))
    {
      throw ReadError(file, lineNumber,
        "malformed section header '" + excerpt(text) + "': the span is not a finite number");
    }
    result.span = span;
    result.spanGiven = true;
    return result;
  }
  result.kind = LineKind::Data;
  return result;
}
} // namespace parsing

std::string formatNumber(double value)
{
  std::ostringstream stream;
  stream << value;
  return stream.str();
}

std::string profileSectionName(const ProfileSection& section, bool withBlade)
{
  std::ostringstream name;
  if (withBlade && !section.blade.empty())
  {
    name << section.blade << ": ";
  }
  name << "Profile " << section.number << " (" << formatNumber(section.spanPercent) << "%)";
  return name.str();
}

namespace
{

void checkCount(const ProfileSection& section, const std::string& what)
{
  if (section.points.size() < 4)
  {
    std::ostringstream reason;
    reason << what << " has " << section.points.size() << " point"
           << (section.points.size() == 1 ? "" : "s")
           << "; at least 4 are needed to fit a curve through it";
    throw ReadError(section.file, section.firstLine, reason.str());
  }
}
} // namespace

//------------------------------------------------------------------------------------------
std::vector<ProfileSection> readPointFile(const std::string& path, bool sections)
{
  const std::vector<std::string> lines = readLines(path);

  // Every comment or blank line between two point rows starts a new section; headers
  // also number the section and may give its span.
  std::vector<ClassifiedLine> kinds;
  kinds.reserve(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i)
  {
    kinds.push_back(classify(lines[i], path, static_cast<int>(i) + 1));
    if (kinds.back().kind == LineKind::Section)
    {
      if (!sections)
      {
        throw ReadError(path, static_cast<int>(i) + 1,
          "section header in a contour file, which must hold a single curve");
      }
    }
  }

  std::vector<ProfileSection> result;
  ProfileSection current;
  bool open = false;
  bool dataSeen = false;
  std::string blade;
  auto close = [&]() {
    if (open)
    {
      result.push_back(std::move(current));
      current = ProfileSection();
      open = false;
    }
  };
  auto start = [&](int lineNumber) {
    close();
    current.file = path;
    current.firstLine = lineNumber;
    current.blade = blade;
    current.number = static_cast<int>(result.size()) + 1;
    open = true;
  };

  for (std::size_t i = 0; i < lines.size(); ++i)
  {
    const int lineNumber = static_cast<int>(i) + 1;
    const ClassifiedLine& kind = kinds[i];
    switch (kind.kind)
    {
      case LineKind::Comment:
      case LineKind::Blank:
        if (sections && open && !current.points.empty())
        {
          close();
        }
        break;
      case LineKind::Title:
        if (open && !current.points.empty())
        {
          close();
        }
        blade = kind.title;
        if (open)
        {
          current.blade = blade;
        }
        break;
      case LineKind::Section:
        start(lineNumber);
        current.number = kind.number;
        current.spanPercent = kind.span;
        current.spanGiven = kind.spanGiven;
        break;
      case LineKind::Data:
      {
        const std::vector<std::string> fields = splitFields(lines[i]);
        double value = 0.0;
        if (!dataSeen &&
          std::none_of(fields.begin(), fields.end(),
            [&value](const std::string& field) { return parseNumber(field, value); }))
        {
          // A row of column names ("x,y,z") before the first point.
          dataSeen = true;
          break;
        }
        dataSeen = true;
        if (fields.size() != 3)
        {
          std::ostringstream reason;
          reason << "expected 3 numbers (X Y Z), found " << fields.size() << " field"
                 << (fields.size() == 1 ? "" : "s") << " in '" << excerpt(lines[i]) << "'";
          throw ReadError(path, lineNumber, reason.str());
        }
        double xyz[3] = { 0.0, 0.0, 0.0 };
        for (std::size_t f = 0; f < 3; ++f)
        {
          if (!parseNumber(fields[f], xyz[f]))
          {
            throw ReadError(path, lineNumber,
              "'" + fields[f] + "' is not a number in '" + excerpt(lines[i]) + "'");
          }
          if (!std::isfinite(xyz[f]))
          {
            throw ReadError(path, lineNumber,
              "'" + fields[f] + "' is not a finite number in '" + excerpt(lines[i]) + "'");
          }
        }
        if (!open)
        {
          start(lineNumber);
        }
        current.points.emplace_back(xyz[0], xyz[1], xyz[2]);
        current.lines.push_back(lineNumber);
        break;
      }
    }
  }
  close();

  if (!sections)
  {
    ProfileSection all;
    all.file = path;
    all.blade = blade;
    for (auto& section : result)
    {
      if (all.firstLine == 0)
      {
        all.firstLine = section.firstLine;
      }
      all.points.insert(all.points.end(), section.points.begin(), section.points.end());
      all.lines.insert(all.lines.end(), section.lines.begin(), section.lines.end());
    }
    if (all.points.empty())
    {
      throw ReadError(path, 0, "no points (expected rows of X Y Z)");
    }
    all.name = blade;
    checkCount(all, "the curve");
    return { all };
  }

  if (result.empty() || std::all_of(result.begin(), result.end(),
                          [](const ProfileSection& s) { return s.points.empty(); }))
  {
    throw ReadError(path, 0, "no points (expected rows of X Y Z)");
  }
  // Sections without a span are spread evenly in file order; a guess, flagged by
  // spanGiven so that callers can tell.
  const std::size_t count = result.size();
  std::set<std::string> blades;
  for (std::size_t i = 0; i < count; ++i)
  {
    ProfileSection& section = result[i];
    if (!section.spanGiven)
    {
      section.spanPercent = count > 1 ? 100.0 * static_cast<double>(i) / (count - 1) : 0.0;
    }
    blades.insert(section.blade);
  }
  for (auto& section : result)
  {
    section.name = profileSectionName(section, blades.size() > 1);
    checkCount(section, "section '" + section.name + "'");
  }
  return result;
}

} // namespace io
} // namespace blockforge
