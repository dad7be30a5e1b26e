// "Did you mean ...?": the known name nearest to a mistyped one, by edit distance (the CLI's unknown
// subcommands and options; also usable for unknown keys in files).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace selfcal {

// The Damerau-Levenshtein distance (optimal string alignment: insertions, deletions, substitutions and
// transpositions of neighbours each cost 1) between a and b, byte by byte.
int EditDistance(std::string_view a, std::string_view b);

// The candidate nearest to `word`, when it is near enough to be a likely typo: distance at most
// max(1, min(3, length of word / 3)), or the candidate begins with `word` (an abbreviation of 2 or more
// characters). Ties go to the first candidate. "" when none is near.
std::string ClosestName(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace selfcal
