// src/cli/support/parse.hpp -- the command's exit codes and one parser per kind of flag value that is
// not a scenario key (lists of numbers, counts, shards), and matrices as JSON.
#pragma once

#include "ffsr/ffsr.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace ffsr::cli {

/// Exit codes: 2 for bad input (arguments, files, models) and for an output that cannot be written
/// (including a reader that closed the pipe), 3 for a numerical failure, 4 when the result moved away
/// from the --expect baseline.
constexpr int kExitInput = 2;
constexpr int kExitNumerical = 3;
constexpr int kExitRegression = 4;

/// Parses "a,b,c" into numbers; throws InputError naming `flag` on a bad or non-finite number or
/// when the count is not one of `counts` (empty: any count >= 1).
std::vector<double> parse_list(const std::string& text, const std::string& flag,
                               std::vector<size_t> counts = {});
Vector3 parse_vec3(const std::string& text, const std::string& flag);
/// A non-negative integer written in decimal digits (no sign, no exponent), or InputError naming `flag`.
std::uint64_t parse_count(const std::string& text, const std::string& flag);
/// --shard K/N: part K (counting from 0) of N.
struct Shard {
  std::uint64_t k = 0, n = 1;
};
/// Parses K/N (0 <= K < N); InputError naming --shard.
Shard parse_shard(const std::string& text);
double deg2rad(double deg);
double rad2deg(double rad);


}  // namespace ffsr::cli
