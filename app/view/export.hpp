#pragma once
// `bvc3d view --export DIR`: the same page as static files that open from disk (file://), where a
// browser may neither fetch files nor import modules. The front end is one classic script, and each
// reply the page would have asked the server for is a script file that hands its bytes (base64) to
// the page (docs/viewer.md#export).
// Takes: the data, the built front end, an output folder and how many samples per trial to keep
// step data for. Gives: DIR/index.html, the page's files, DIR/data/*.js.
#include <filesystem>

#include "view/view_data.hpp"

namespace bvc3d::view {

struct ExportSummary {
    std::size_t files = 0, bytes = 0, steps = 0;
};

// Steps: the samples whose returns and rates are written, evenly spaced over each trial (the
// trajectory and metrics are complete; the slider shows the nearest exported step). The folder is
// written under a temporary name and renamed when complete. An existing folder that is not empty is
// refused, unless `replace` and it is an earlier export (index.html and data/ in it), which is then
// replaced whole.
ExportSummary export_view(ViewData& data, const std::filesystem::path& web_dir, const std::filesystem::path& out,
                          std::size_t steps, bool replace = false);

}  // namespace bvc3d::view
