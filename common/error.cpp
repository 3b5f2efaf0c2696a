#include "common/error.hpp"

#include <cmath>
#include <cstdlib>

namespace fem {

NotImplemented::NotImplemented(std::string_view exercise_id, std::string_view function,
                               std::string_view docs)
    // The link goes on a line of its own, so that Catch2, which wraps a message at 80 columns,
    // never breaks it (tools/exercises.py check keeps every link shorter than a line).
    : std::logic_error(str("exercise ", exercise_id, " (", function, ") is not implemented yet; see\n",
                           docs))
{
}

bool exercise_stubbed(std::string_view exercise_id)
{
    static const std::string stubbed = [] {
        const char* value = std::getenv("FEM_STUB_EXERCISE");
        return std::string(value ? value : "");
    }();
    std::string_view list = stubbed;
    while (!list.empty()) {
        const auto comma = list.find(',');
        if (list.substr(0, comma) == exercise_id)
            return true;
        if (comma == std::string_view::npos)
            break;
        list.remove_prefix(comma + 1);
    }
    return false;
}

void require_positive(double value, std::string_view what)
{
    if (!(std::isfinite(value) && value > 0.0))
        throw Error(str(what, " must be a finite number > 0, got ", value));
}

void require_finite(double value, std::string_view what)
{
    if (!std::isfinite(value))
        throw Error(str(what, " must be a finite number, got ", value));
}

}  // namespace fem
