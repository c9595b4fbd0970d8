/**
 * @file PointFiles.h
 * @brief Private to the point-set reader (not installed): the text layer of its input
 * files (lines whatever their line ends, fields, locale-independent numbers, the kind of
 * each line of a point file), shared by the point-file parser (PointFiles.cpp) and the
 * reader of description files and whole sets (TurboPointSets.cpp).
 *
 * It exists so that those two responsibilities can live in two files without writing
 * the text handling twice.
 */
#pragma once

#include "TurboPointSets.h"

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace blockforge
{
namespace io
{
namespace parsing
{
bool isBlank(char c);
std::string trim(const std::string& text);
std::string lower(std::string text);
std::string upper(std::string text);

/// Splits at blanks, tabs, commas and semicolons (CSV and whitespace files alike).
std::vector<std::string> splitFields(const std::string& text);

/// Short, printable excerpt of a row for error messages.
std::string excerpt(const std::string& text);

/// Parses a whole token as a number; locale-independent (ParaView may run with a
/// decimal-comma locale), accepts a leading '+' and Fortran's D exponent.
/// Returns false if the token is not a number; NaN and infinities parse (callers reject
/// them with a specific message).
bool parseNumber(const std::string& token, double& value);

/// The lines of a file without their line ends (LF, CRLF or lone CR) and without a UTF-8
/// byte order mark. @p maxBytes limits how much is read (0: all).
std::vector<std::string> readLines(const std::string& path, std::size_t maxBytes = 0);

enum class LineKind
{
  Blank,
  Comment,
  Title,   // "## name"
  Section, // "# Profile k at s%"
  Data
};

struct ClassifiedLine
{
  LineKind kind = LineKind::Blank;
  std::string title;
  int number = 0;
  double span = std::numeric_limits<double>::quiet_NaN();
  bool spanGiven = false;
};

/// Recognises section headers: a `#` line with the words "Profile k" or "Section k"
/// anywhere ("# Profile 3 at 16.6667%", "# IGV Profile 1", "# Rotor1 Profile 2", any
/// case, tabs), optionally followed by "at s%" or "s%" (the span). Any other `#` or `!`
/// line is an ordinary comment (which still starts a new section in a profile file). A
/// header whose span is malformed is an error, since a silently dropped span would put
/// the section at a guessed place.
ClassifiedLine classify(const std::string& raw, const std::string& file, int lineNumber);
} // namespace parsing
} // namespace io
} // namespace blockforge
