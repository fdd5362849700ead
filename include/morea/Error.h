// MultiObjectiveRegistration core: the one exception type the core throws.
#ifndef morea_Error_h
#define morea_Error_h

#include <stdexcept>
#include <string>

namespace morea
{
/** Raised for bad input or an impossible request; the message is meant for the user. */
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string & message)
    : std::runtime_error(message)
  {}
};
} // namespace morea

#endif
