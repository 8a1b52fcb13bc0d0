#pragma once
// The Python package's modules as child processes of the program (the figures of `paper`, `flight`,
// `sweep`, `summarize` and `localize`): one way to find the interpreter and run a module.
#include <string>
#include <vector>

namespace bvc3d::cli {

// How a module of the Python package runs: the interpreter (BVC3D_PYTHON, else the one found at
// build time) and the PYTHONPATH that finds the package (BVC3D_PYTHONPATH, else the build's python
// folder, then any PYTHONPATH already set).
struct PythonCommand {
    std::string python, pythonpath;
    // The command as a shell line that works as printed: `PYTHONPATH=... /usr/bin/python3 -m MODULE ARGS`.
    std::string shell_line(const std::string& module, const std::vector<std::string>& args) const;
};
PythonCommand python_command();

// How a module's run ended: its exit status (-1 if it could not run or died by a signal) and, when
// kept, all it wrote to standard error.
struct ModuleRun {
    int status = -1;
    std::string error_text;
    std::string last_error_line() const;  // the last non-empty line of error_text
};

// Runs `python3 -m MODULE ARGS...` as a child process, no shell, after our own output. Its standard
// error goes to ours, or with `keep_stderr` into the result (to say why it failed, or to show it).
ModuleRun run_python_module(const std::string& module, const std::vector<std::string>& args, bool keep_stderr = false);

}  // namespace bvc3d::cli
