#pragma once
// User-facing errors. The CLI prints what() and exits non-zero; Python sees ValueError.
#include <stdexcept>
#include <string>

namespace bvc3d {

// Bad input from a user: a config file, a mesh, command-line values, a scan.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Bad configuration: names the file, the key (a dotted path such as `objects[2].size`) and why.
class ConfigError : public InputError {
public:
    ConfigError(const std::string& file, const std::string& key, const std::string& reason)
        : InputError(format(file, key, reason)), file_(file), key_(key), reason_(reason) {}
    const std::string& file() const { return file_; }
    const std::string& key() const { return key_; }
    const std::string& reason() const { return reason_; }

private:
    static std::string format(const std::string& file, const std::string& key, const std::string& reason) {
        std::string m = file.empty() ? std::string("<config>") : file;
        if (!key.empty()) m += ": key '" + key + "'";
        return m + ": " + reason;
    }
    std::string file_, key_, reason_;
};

}  // namespace bvc3d
