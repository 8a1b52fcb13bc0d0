#include "python_module.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>

namespace bvc3d::cli {

namespace {

// Text as one shell word: as it is when safe, else single-quoted.
std::string shell_word(const std::string& s) {
    const bool safe = !s.empty() && s.find_first_not_of(
                                        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                        "_-./:=+,@%") == std::string::npos;
    if (safe) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// All that can still be read from `fd`, until its writer closes it.
std::string read_all(int fd) {
    std::string text;
    char buf[4096];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        text.append(buf, static_cast<std::size_t>(n));
    }
    return text;
}

}  // namespace

std::string PythonCommand::shell_line(const std::string& module, const std::vector<std::string>& args) const {
    std::string line = "PYTHONPATH=" + shell_word(pythonpath);
    for (const auto& word : {shell_word(python), std::string("-m"), module}) line.append(" ").append(word);
    for (const auto& a : args) line.append(" ").append(shell_word(a));
    return line;
}

PythonCommand python_command() {
    const char* py_env = std::getenv("BVC3D_PYTHON");
    const char* path_env = std::getenv("BVC3D_PYTHONPATH");
    PythonCommand c{py_env && *py_env ? py_env : BVC3D_PYTHON, path_env && *path_env ? path_env : BVC3D_PYTHON_DIR};
    if (const char* existing = std::getenv("PYTHONPATH"); existing && *existing && c.pythonpath != existing)
        c.pythonpath += std::string(":") + existing;
    return c;
}

std::string ModuleRun::last_error_line() const {
    std::string tail = error_text;
    while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
    const auto nl = tail.rfind('\n');
    return nl == std::string::npos ? tail : tail.substr(nl + 1);
}

ModuleRun run_python_module(const std::string& module, const std::vector<std::string>& args, bool keep_stderr) {
    const PythonCommand command = python_command();
    std::vector<std::string> argv_text{command.python, "-m", module};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_text) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(stdout);  // our lines first, then the module's
    std::fflush(stderr);
    int pipe_fds[2] = {-1, -1};
    if (keep_stderr && ::pipe(pipe_fds) != 0) return {};
    const pid_t pid = ::fork();
    if (pid < 0) {
        if (keep_stderr) {
            ::close(pipe_fds[0]);
            ::close(pipe_fds[1]);
        }
        return {};
    }
    if (pid == 0) {
        if (keep_stderr) {
            ::close(pipe_fds[0]);
            ::dup2(pipe_fds[1], STDERR_FILENO);
            ::close(pipe_fds[1]);
        }
        ::setenv("PYTHONPATH", command.pythonpath.c_str(), 1);
        ::execv(command.python.c_str(), argv.data());
        std::perror(("bvc3d: cannot run " + command.python).c_str());
        ::_exit(127);
    }
    ModuleRun run;
    if (keep_stderr) {
        ::close(pipe_fds[1]);
        run.error_text = read_all(pipe_fds[0]);
        ::close(pipe_fds[0]);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

}  // namespace bvc3d::cli
