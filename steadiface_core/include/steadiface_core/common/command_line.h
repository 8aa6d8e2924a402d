#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace steadiface {

/// The command-line parser every steadiface tool shares: options
/// "--name VALUE" and switches "--name", each bound to a variable, and
/// (optionally) positional arguments. A value is checked when it is read:
/// a number must be a whole number of its type, a missing value is an
/// error, and so is an argument no one declared. "--help" and "-h" ask for
/// the usage.
///
///   CommandLine cl;
///   cl.String("--in", &in).Double("--duration", &duration).Flag("--quiet", &quiet);
///   std::string error;
///   switch (cl.Parse(argc, argv, &error)) { ... }
class CommandLine {
 public:
  enum class Result {
    kOk,
    kHelp,   ///< --help or -h was given
    kError,  ///< *error says which argument and why
  };
  /// Parses a value: false when it is not one (the parser reports it).
  using ValueParser = std::function<bool(const std::string&)>;

  /// "--name": sets *value to true.
  CommandLine& Flag(const std::string& name, bool* value);
  /// "--name": sets *value to false.
  CommandLine& ClearFlag(const std::string& name, bool* value);
  CommandLine& String(const std::string& name, std::string* value);
  /// Repeatable: each occurrence appends its value.
  CommandLine& Strings(const std::string& name, std::vector<std::string>* values);
  CommandLine& Double(const std::string& name, double* value);
  CommandLine& Int(const std::string& name, int* value);
  CommandLine& UInt64(const std::string& name, uint64_t* value);
  /// "--name VALUE" read by `parse`; `what` describes a valid value for the
  /// error message (e.g. "WxH").
  CommandLine& Value(const std::string& name, const std::string& what, ValueParser parse);
  /// Arguments that do not start with '-', in order; without this, any is
  /// an error.
  CommandLine& Positional(std::vector<std::string>* values);

  Result Parse(int argc, const char* const* argv, std::string* error) const;
  Result Parse(int argc, char** argv, std::string* error) const {
    return Parse(argc, const_cast<const char* const*>(argv), error);
  }

  /// The tools' shared start: parses argv. --help or -h prints `usage` to
  /// `out` (exit status 0); an unknown or malformed argument prints
  /// "<tool>: <error>" and the usage to `err` (2); so does a missing
  /// required argument (`ready` returns false after parsing; null: none is
  /// required). True when the tool should run; otherwise *exit_status says
  /// how it ends.
  bool Start(int argc, const char* const* argv, const std::string& tool,
             const std::string& usage, const std::function<bool()>& ready, std::ostream& out,
             std::ostream& err, int* exit_status) const;
  bool Start(int argc, char** argv, const std::string& tool, const std::string& usage,
             const std::function<bool()>& ready, std::ostream& out, std::ostream& err,
             int* exit_status) const {
    return Start(argc, const_cast<const char* const*>(argv), tool, usage, ready, out, err,
                 exit_status);
  }

 private:
  struct Option {
    bool takes_value = false;
    std::string what;  // for errors
    ValueParser parse;
  };
  CommandLine& Add(const std::string& name, Option option);

  std::map<std::string, Option> options_;
  std::vector<std::string>* positional_ = nullptr;
};

/// Strict number parsing for the tools: the whole string must be the number.
bool ParseDouble(const std::string& text, double* value);
bool ParseInt(const std::string& text, int* value);
bool ParseUInt64(const std::string& text, uint64_t* value);

}  // namespace steadiface
