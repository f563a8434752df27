#include "grbd/core/error.hpp"

namespace grbd {

namespace {
std::string not_implemented_message(std::string_view exercise, std::string_view title,
                                    std::string_view chapter, std::string_view file) {
  std::string message = "[NotImplemented] ";
  message.append(exercise).append(" (").append(title).append(") is not implemented yet: read ");
  message.append(chapter).append(" and fill in the marked function in ").append(file).append(".");
  return message;
}
}  // namespace

NotImplemented::NotImplemented(std::string_view exercise, std::string_view title,
                               std::string_view chapter, std::string_view file)
    : std::logic_error(not_implemented_message(exercise, title, chapter, file)),
      exercise_(exercise) {}

}  // namespace grbd
