#pragma once
// `bvc3d view`'s web server: the page's files and the data API over HTTP on 127.0.0.1 only,
// read-only (GET), several browsers at once (a pool of threads).
// Takes: the data (view_data.hpp) and the folder of the built front end. Gives: a server that runs
// until `stop` is set (Ctrl-C).
#include <atomic>
#include <filesystem>
#include <functional>

#include "view/view_data.hpp"

namespace bvc3d::view {

// Binds 127.0.0.1:port (0: a free port), calls `on_ready(port)`, then serves until `stop` is set.
// InputError if the port cannot be bound.
void serve(ViewData& data, const std::filesystem::path& web_dir, int port, const std::atomic<bool>& stop,
           const std::function<void(int)>& on_ready);

}  // namespace bvc3d::view
