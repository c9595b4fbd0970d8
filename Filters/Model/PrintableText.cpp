#include "PrintableText.h"

#include <cstdio>

namespace blockforge
{
namespace
{
/// Length of the valid UTF-8 sequence starting at text[i] (1 to 4), or 0 if invalid
/// (overlong forms, surrogates and code points above U+10FFFF are invalid too).
std::size_t sequenceLength(const std::string& text, std::size_t i)
{
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  std::size_t length = 0;
  unsigned int low = 0x80, high = 0xBF; // allowed range of the second byte
  if (lead < 0x80)
  {
    return 1;
  }
  if (lead >= 0xC2 && lead <= 0xDF)
  {
    length = 2;
  }
  else if (lead >= 0xE0 && lead <= 0xEF)
  {
    length = 3;
    low = lead == 0xE0 ? 0xA0 : 0x80;
    high = lead == 0xED ? 0x9F : 0xBF;
  }
  else if (lead >= 0xF0 && lead <= 0xF4)
  {
    length = 4;
    low = lead == 0xF0 ? 0x90 : 0x80;
    high = lead == 0xF4 ? 0x8F : 0xBF;
  }
  else
  {
    return 0;
  }
  if (i + length > text.size())
  {
    return 0;
  }
  if (byte(i + 1) < low || byte(i + 1) > high)
  {
    return 0;
  }
  for (std::size_t k = 2; k < length; ++k)
  {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF)
    {
      return 0;
    }
  }
  return length;
}
} // namespace

std::string printableText(const std::string& text)
{
  std::string result;
  result.reserve(text.size());
  for (std::size_t i = 0; i < text.size();)
  {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const std::size_t length = sequenceLength(text, i);
    if (length == 0 || (c < 0x20 && c != '\n' && c != '\t') || c == 0x7F)
    {
      char escaped[5];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", c);
      result += escaped;
      ++i;
      continue;
    }
    result.append(text, i, length);
    i += length;
  }
  return result;
}
} // namespace blockforge
