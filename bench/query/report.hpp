#pragma once
// --report DIR: a self-contained HTML page (inline SVG, no scripts, no network).
#include <filesystem>
#include <vector>

#include "output.hpp"

namespace tightbvh::bench {

void write_report(const std::filesystem::path& dir, const RunInfo& info, const std::vector<Row>& rows,
                  const Input& input);

}  // namespace tightbvh::bench
