/**
 * @file PrintableText.h
 * @brief Messages that survive any bytes: file names, template names and input lines are
 * copied into error messages as they are, and a stray byte that is not UTF-8 would make
 * the message unreadable for Python (None instead of a str) and for ParaView's Output
 * Messages. printableText() escapes such bytes.
 */
#pragma once

#include <string>

namespace blockforge
{
/// `text` with every byte that is not part of a valid UTF-8 sequence (and every control
/// character other than newline and tab) written as \xNN; valid UTF-8 is kept as it is.
std::string printableText(const std::string& text);
} // namespace blockforge
