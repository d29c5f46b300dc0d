#include "fibernet/solve/result.hpp"

namespace fibernet {

std::string to_string(SolveStatus s) {
    switch (s) {
        case SolveStatus::Converged: return "converged";
        case SolveStatus::IterationLimit: return "iteration_limit";
        case SolveStatus::LineSearchFailed: return "line_search_failed";
        case SolveStatus::NonFinite: return "non_finite";
        case SolveStatus::Stalled: return "stalled";
        case SolveStatus::Failed: return "failed";
    }
    return "?";
}

}  // namespace fibernet
