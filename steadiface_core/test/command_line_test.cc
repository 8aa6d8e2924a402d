#include "steadiface_core/common/command_line.h"

#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace steadiface {
namespace {

using Result = CommandLine::Result;

// argv with a program name in front.
Result ParseArgs(const CommandLine& cl, std::vector<std::string> args, std::string* error) {
  args.insert(args.begin(), "tool");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  return cl.Parse(static_cast<int>(argv.size()), argv.data(), error);
}

struct Bound {
  std::string in;
  std::vector<std::string> params;
  double duration = 3.0;
  int width = 0, height = 0;
  uint64_t seed = 1;
  bool quiet = false, face = true;
  CommandLine cl;
  Bound() {
    cl.String("--in", &in).Strings("--params", &params).Double("--duration", &duration);
    cl.UInt64("--seed", &seed).Flag("--quiet", &quiet).ClearFlag("--no-face", &face);
    cl.Value("--size", "WxH", [this](const std::string& v) {
      return std::sscanf(v.c_str(), "%dx%d", &width, &height) == 2;
    });
  }
};

TEST(CommandLineTest, EveryKindOfOptionIsReadIntoItsVariable) {
  Bound b;
  std::string error;
  ASSERT_EQ(ParseArgs(b.cl,
                {"--in", "a.bag", "--params", "x.yaml", "--duration", "2.5e0", "--params", "y.yaml",
                 "--seed", "18446744073709551615", "--quiet", "--no-face", "--size", "640x360"},
                &error),
            Result::kOk)
      << error;
  EXPECT_EQ(b.in, "a.bag");
  EXPECT_EQ(b.params, (std::vector<std::string>{"x.yaml", "y.yaml"}));  // in order
  EXPECT_EQ(b.duration, 2.5);
  EXPECT_EQ(b.seed, UINT64_MAX);
  EXPECT_TRUE(b.quiet);
  EXPECT_FALSE(b.face);
  EXPECT_EQ(b.width, 640);
  EXPECT_EQ(b.height, 360);
}

TEST(CommandLineTest, WithoutArgumentsTheDefaultsStay) {
  Bound b;
  std::string error;
  ASSERT_EQ(ParseArgs(b.cl, {}, &error), Result::kOk);
  EXPECT_EQ(b.duration, 3.0);
  EXPECT_EQ(b.seed, 1u);
  EXPECT_FALSE(b.quiet);
  EXPECT_TRUE(b.face);
}

TEST(CommandLineTest, BadArgumentsAreErrorsThatNameThem) {
  struct Case {
    std::vector<std::string> args;
    std::string error;
  };
  const std::vector<Case> cases = {
      {{"--duration", "2s"}, "--duration takes a number, not '2s'"},
      {{"--duration", ""}, "--duration takes a number, not ''"},
      {{"--seed", "-1"}, "--seed takes a non-negative integer, not '-1'"},
      {{"--seed", "1.5"}, "--seed takes a non-negative integer, not '1.5'"},
      {{"--size", "640"}, "--size takes WxH, not '640'"},
      {{"--in"}, "--in needs a value"},
      {{"--frobnicate"}, "unknown argument '--frobnicate'"},
      {{"a.bag"}, "unknown argument 'a.bag'"},  // no positional arguments declared
  };
  for (const Case& c : cases) {
    Bound b;
    std::string error;
    EXPECT_EQ(ParseArgs(b.cl, c.args, &error), Result::kError) << c.args[0];
    EXPECT_EQ(error, c.error);
  }
}

TEST(CommandLineTest, HelpWinsWhereverItIs) {
  for (const std::string h : {"--help", "-h"}) {
    Bound b;
    std::string error;
    EXPECT_EQ(ParseArgs(b.cl, {"--in", "a.bag", h, "--frobnicate"}, &error), Result::kHelp);
  }
}

TEST(CommandLineTest, PositionalArgumentsAreCollectedInOrderWhenDeclared) {
  std::vector<std::string> files;
  double fps = 30.0;
  CommandLine cl;
  cl.Double("--fps", &fps).Positional(&files);
  std::string error;
  ASSERT_EQ(ParseArgs(cl, {"a.mp4", "--fps", "25", "b.mp4"}, &error), Result::kOk) << error;
  EXPECT_EQ(files, (std::vector<std::string>{"a.mp4", "b.mp4"}));
  EXPECT_EQ(fps, 25.0);
  EXPECT_EQ(ParseArgs(cl, {"-x"}, &error), Result::kError);
}

TEST(CommandLineTest, NumbersMustBeWholeAndInRange) {
  double d = 0;
  int i = 0;
  uint64_t u = 0;
  EXPECT_TRUE(ParseDouble("-1.25", &d));
  EXPECT_EQ(d, -1.25);
  EXPECT_FALSE(ParseDouble("1e999", &d));
  EXPECT_FALSE(ParseDouble("1.0x", &d));
  EXPECT_TRUE(ParseInt("-7", &i));
  EXPECT_EQ(i, -7);
  EXPECT_FALSE(ParseInt("3000000000", &i));
  EXPECT_FALSE(ParseInt("7.0", &i));
  EXPECT_TRUE(ParseUInt64("0", &u));
  EXPECT_FALSE(ParseUInt64("18446744073709551616", &u));
}

}  // namespace
// The tools' shared start: help to `out` with 0, errors and missing
// required arguments to `err` with the usage and 2, else run.
TEST(CommandLineTest, StartEndsOnHelpErrorsAndMissingArgumentsAndElseRuns) {
  std::string in;
  CommandLine cl;
  cl.String("--in", &in);
  const auto ready = [&in] { return !in.empty(); };
  auto start = [&](std::vector<const char*> argv, std::string* out, std::string* err, int* code) {
    argv.insert(argv.begin(), "tool");
    std::ostringstream o, e;
    const bool run = cl.Start(static_cast<int>(argv.size()), argv.data(), "tool", "usage: tool\n",
                              ready, o, e, code);
    *out = o.str();
    *err = e.str();
    return run;
  };
  std::string out, err;
  int code = -1;
  EXPECT_FALSE(start({"--help"}, &out, &err, &code));
  EXPECT_EQ(code, 0);
  EXPECT_EQ(out, "usage: tool\n");
  EXPECT_EQ(err, "");
  EXPECT_FALSE(start({"--bogus"}, &out, &err, &code));
  EXPECT_EQ(code, 2);
  EXPECT_EQ(err, "tool: unknown argument '--bogus'\nusage: tool\n");
  EXPECT_FALSE(start({}, &out, &err, &code));  // --in is required
  EXPECT_EQ(code, 2);
  EXPECT_EQ(err, "usage: tool\n");
  code = -1;
  EXPECT_TRUE(start({"--in", "x.bag"}, &out, &err, &code));
  EXPECT_EQ(code, -1);
  EXPECT_EQ(in, "x.bag");
}

}  // namespace steadiface
