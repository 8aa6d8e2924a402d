#include "steadiface_core/common/command_line.h"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <utility>

namespace steadiface {

bool ParseDouble(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (*end != '\0' || errno == ERANGE) return false;
  *value = v;
  return true;
}

bool ParseInt(const std::string& text, int* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE || v < INT_MIN || v > INT_MAX) return false;
  *value = static_cast<int>(v);
  return true;
}

bool ParseUInt64(const std::string& text, uint64_t* value) {
  if (text.empty() || text[0] == '-') return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE) return false;
  *value = static_cast<uint64_t>(v);
  return true;
}

CommandLine& CommandLine::Add(const std::string& name, Option option) {
  options_[name] = std::move(option);
  return *this;
}

CommandLine& CommandLine::Flag(const std::string& name, bool* value) {
  return Add(name, {false, "", [value](const std::string&) { return *value = true; }});
}

CommandLine& CommandLine::ClearFlag(const std::string& name, bool* value) {
  return Add(name, {false, "", [value](const std::string&) {
                      *value = false;
                      return true;
                    }});
}

CommandLine& CommandLine::String(const std::string& name, std::string* value) {
  return Add(name, {true, "a value", [value](const std::string& v) {
                      *value = v;
                      return true;
                    }});
}

CommandLine& CommandLine::Strings(const std::string& name, std::vector<std::string>* values) {
  return Add(name, {true, "a value", [values](const std::string& v) {
                      values->push_back(v);
                      return true;
                    }});
}

CommandLine& CommandLine::Double(const std::string& name, double* value) {
  return Add(name, {true, "a number", [value](const std::string& v) {
                      return ParseDouble(v, value);
                    }});
}

CommandLine& CommandLine::Int(const std::string& name, int* value) {
  return Add(name, {true, "an integer", [value](const std::string& v) {
                      return ParseInt(v, value);
                    }});
}

CommandLine& CommandLine::UInt64(const std::string& name, uint64_t* value) {
  return Add(name, {true, "a non-negative integer", [value](const std::string& v) {
                      return ParseUInt64(v, value);
                    }});
}

CommandLine& CommandLine::Value(const std::string& name, const std::string& what,
                                ValueParser parse) {
  return Add(name, {true, what, std::move(parse)});
}

CommandLine& CommandLine::Positional(std::vector<std::string>* values) {
  positional_ = values;
  return *this;
}

CommandLine::Result CommandLine::Parse(int argc, const char* const* argv,
                                       std::string* error) const {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return Result::kHelp;
    const auto it = options_.find(a);
    if (it == options_.end()) {
      if (positional_ && !a.empty() && a[0] != '-') {
        positional_->push_back(a);
        continue;
      }
      *error = "unknown argument '" + a + "'";
      return Result::kError;
    }
    const Option& o = it->second;
    if (!o.takes_value) {
      o.parse("");
      continue;
    }
    if (i + 1 >= argc) {
      *error = a + " needs " + o.what;
      return Result::kError;
    }
    const std::string v = argv[++i];
    if (!o.parse(v)) {
      *error = a + " takes " + o.what + ", not '" + v + "'";
      return Result::kError;
    }
  }
  return Result::kOk;
}

bool CommandLine::Start(int argc, const char* const* argv, const std::string& tool,
                        const std::string& usage, const std::function<bool()>& ready,
                        std::ostream& out, std::ostream& err, int* exit_status) const {
  std::string error;
  const Result parsed = Parse(argc, argv, &error);
  if (parsed == Result::kHelp) {
    out << usage;
    *exit_status = 0;
    return false;
  }
  if (parsed == Result::kError) err << tool << ": " << error << "\n";
  if (parsed == Result::kError || (ready && !ready())) {
    err << usage;
    *exit_status = 2;
    return false;
  }
  return true;
}

}  // namespace steadiface
