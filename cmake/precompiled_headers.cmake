# One precompiled header for the whole build. Nearly every source file
# includes the standard library's, Eigen's, fmt's and JSON's headers, about
# 150,000-250,000 lines, and parsed them again in each of the build's
# hundred-odd files: a part of a fresh build's time, and so of CI's
# (docs/benchmarks.md, "CI").
#
# The libraries and the tests use it, each file about a second faster (a
# tenth to a fifth). The stage mains do not: a main at -O1 (stages/) took
# 18.7 s with it instead of 11.2, most likely because the header's inline
# functions keep the -O3 they were parsed with.
#
# GCC only: an unusable precompiled header (a file compiled with other
# flags) makes GCC parse the headers as text, while clang, which builds the
# fuzz harnesses with sanitizers, stops with an error instead.
# -DCMAKE_DISABLE_PRECOMPILE_HEADERS=ON builds without it.
#
#   op2gs_precompiled_headers(<target>)   the target's files use it

set(OP2GS_PRECOMPILED_HEADERS
    <algorithm> <array> <cmath> <cstdint> <filesystem> <functional> <map> <memory>
    <optional> <string> <string_view> <unordered_map> <utility> <vector>
    <Eigen/Core> <Eigen/Geometry> <fmt/format.h> <nlohmann/json.hpp> <spdlog/spdlog.h>)

if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # Built once; the others reuse it, so its flags are theirs.
  add_library(op2gs_pch STATIC ${CMAKE_CURRENT_LIST_DIR}/precompiled_headers.cc)
  target_link_libraries(op2gs_pch PUBLIC Eigen3::Eigen TBB::tbb fmt::fmt spdlog::spdlog
                                         nlohmann_json::nlohmann_json)
  target_precompile_headers(op2gs_pch PRIVATE ${OP2GS_PRECOMPILED_HEADERS})
endif()

function(op2gs_precompiled_headers target)
  if(TARGET op2gs_pch)
    target_precompile_headers(${target} REUSE_FROM op2gs_pch)
  endif()
endfunction()
