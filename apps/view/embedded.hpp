#pragma once
// Text files compiled into the binary by embed.cmake, so that `tightbvh` writes pages that work
// offline without finding anything at run time.
#include <string>

namespace tightbvh::view {

// three.js's ES module (third_party/three, installed by scripts/setup); empty when it was not
// installed at configure time (the page then draws with its canvas fallback).
[[nodiscard]] std::string three_js_source();
// apps/view/page.html.
[[nodiscard]] std::string page_template();

}  // namespace tightbvh::view
