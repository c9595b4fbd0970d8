#include "Errors.h"

namespace blockforge
{
namespace model
{
namespace
{
std::string composeMessage(
  const std::string& file, int line, const std::string& entity, const std::string& message)
{
  std::string text = file.empty() ? std::string("<template>") : file;
  if (line > 0)
  {
    text += ":" + std::to_string(line);
  }
  text += ": ";
  if (!entity.empty())
  {
    text += entity + ": ";
  }
  return text + message;
}
} // namespace

TemplateError::TemplateError(const std::string& file, int line, const std::string& entity,
  const std::string& message)
  : std::runtime_error(composeMessage(file, line, entity, message))
  , File(file)
  , Entity(entity)
  , Line(line)
{
}
} // namespace model
} // namespace blockforge
