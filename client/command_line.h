// The `neuralmesh` command line: a subcommand, its positional arguments and its flags.
//
// Flags are defined with ABSL_FLAG in client/main.cc only; this parser sets them through
// Abseil's flag registry (absl/flags/reflection.h), so that each subcommand accepts exactly
// the flags it documents and every mistake gets a message that names it. Accepted forms:
// --name=value, --name value, -name value, --bool_flag, --nobool_flag, hyphens or underscores
// in names (--out-dir and --out_dir are the same flag), and the alias -o for --output.
#ifndef NEURALMESH_CLIENT_COMMAND_LINE_H_
#define NEURALMESH_CLIENT_COMMAND_LINE_H_

#include <functional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::client {

// What a subcommand received.
struct ParsedArgs {
  std::vector<std::string> positional;
  std::set<std::string> flags_given;  // Canonical flag names (underscores) set on the line.

  // Whether `flag` (hyphens or underscores) was set on the command line.
  bool Has(const std::string& flag) const;
};

struct Subcommand {
  std::string name;
  std::string usage;               // Shown after "usage: neuralmesh ", e.g. "stats MESH [--json]".
  std::string summary;             // One line for the command list.
  std::string description;         // A paragraph for the command's --help.
  std::vector<std::string> flags;  // Canonical names of the flags this subcommand accepts.
  // Runs the subcommand once its flags are set. Its status becomes the exit code.
  std::function<absl::Status(const ParsedArgs&)> run;
};

// Splits `args` (argv without the program name) into the subcommand's positional arguments
// and flags, and sets each flag. Returns INVALID_ARGUMENT naming the flag when it is unknown,
// not accepted by `command`, lacks a value or has a malformed one.
absl::StatusOr<ParsedArgs> ParseSubcommandArgs(const Subcommand& command,
                                               const std::vector<std::string>& args);

// Writes the usage, summary and every accepted flag of `command` with its help text and
// default value.
void PrintSubcommandHelp(const Subcommand& command, std::ostream& out);

// Writes the list of subcommands.
void PrintCommandList(const std::vector<Subcommand>& commands, std::ostream& out);

// The whole command line: finds the subcommand in argv[1], handles --help / -h / `help CMD`
// and --version / `version` (writes `version` and a line break), parses the flags and runs the
// subcommand. Errors go to `err` as "neuralmesh CMD: message". Returns the process exit code:
// 0 on success, 1 on a failed command, 2 on a usage error.
int RunCommandLine(int argc, char** argv, const std::vector<Subcommand>& commands,
                   absl::string_view version,
                   std::ostream& out, std::ostream& err);

}  // namespace neuralmesh::client

#endif  // NEURALMESH_CLIENT_COMMAND_LINE_H_
