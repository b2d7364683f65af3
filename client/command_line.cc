#include "client/command_line.h"

#include <algorithm>
#include <map>

#include "absl/flags/commandlineflag.h"
#include "absl/flags/reflection.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "absl/time/time.h"

namespace neuralmesh::client {
namespace {

std::string Canonical(const std::string& name) { return absl::StrReplaceAll(name, {{"-", "_"}}); }

bool IsHelp(const std::string& arg) {
  return arg == "--help" || arg == "-help" || arg == "-h" || arg == "--helpfull";
}

// Whether `arg` looks like a flag rather than a positional argument or a negative number.
bool IsFlagToken(const std::string& arg) {
  if (arg.size() < 2 || arg[0] != '-') return false;
  const char c = arg[1] == '-' ? (arg.size() > 2 ? arg[2] : '\0') : arg[1];
  return c != '\0' && !(c >= '0' && c <= '9') && c != '.';
}

const Subcommand* FindCommand(const std::vector<Subcommand>& commands, const std::string& name) {
  for (const Subcommand& c : commands) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

// Breaks `text` into lines of at most `width` characters, each prefixed with `indent`.
std::string Wrap(const std::string& text, size_t width, const std::string& indent) {
  std::string out;
  size_t line = 0;
  for (absl::string_view word : absl::StrSplit(text, ' ', absl::SkipEmpty())) {
    if (line > 0 && line + 1 + word.size() > width) {
      out += "\n";
      line = 0;
    }
    if (line == 0) {
      out += indent;
    } else {
      out += ' ';
      ++line;
    }
    absl::StrAppend(&out, word);
    line += word.size();
  }
  return out;
}

}  // namespace

bool ParsedArgs::Has(const std::string& flag) const {
  return flags_given.count(Canonical(flag)) > 0;
}

absl::StatusOr<ParsedArgs> ParseSubcommandArgs(const Subcommand& command,
                                               const std::vector<std::string>& args) {
  // Canonical name -> name as documented, for the flags this subcommand accepts.
  std::map<std::string, std::string> accepted;
  for (const std::string& f : command.flags) accepted[Canonical(f)] = f;

  ParsedArgs parsed;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--") {
      parsed.positional.insert(parsed.positional.end(), args.begin() + i + 1, args.end());
      break;
    }
    if (!IsFlagToken(arg)) {
      parsed.positional.push_back(arg);
      continue;
    }
    std::string body = arg.substr(arg[1] == '-' ? 2 : 1);
    std::string value;
    bool has_value = false;
    if (const size_t eq = body.find('='); eq != std::string::npos) {
      value = body.substr(eq + 1);
      body = body.substr(0, eq);
      has_value = true;
    }
    std::string name = body == "o" ? "output" : Canonical(body);
    absl::CommandLineFlag* flag = accepted.count(name) ? absl::FindCommandLineFlag(name) : nullptr;
    // --noflag for a boolean flag.
    if (flag == nullptr && absl::StartsWith(name, "no") && !has_value &&
        accepted.count(name.substr(2))) {
      absl::CommandLineFlag* negated = absl::FindCommandLineFlag(name.substr(2));
      if (negated != nullptr && negated->IsOfType<bool>()) {
        flag = negated;
        name = name.substr(2);
        value = "false";
        has_value = true;
      }
    }
    if (flag == nullptr) {
      if (absl::FindCommandLineFlag(name) != nullptr) {
        return absl::InvalidArgumentError(absl::StrCat("flag ", arg, " does not apply to `",
                                                       command.name, "` (see neuralmesh ",
                                                       command.name, " --help)"));
      }
      return absl::InvalidArgumentError(
          absl::StrCat("unknown flag ", arg, " (see neuralmesh ", command.name, " --help)"));
    }
    const std::string shown = "--" + accepted[name];
    if (!has_value) {
      if (flag->IsOfType<bool>()) {
        value = "true";
      } else if (i + 1 < args.size()) {
        value = args[++i];
      } else {
        return absl::InvalidArgumentError(absl::StrCat("flag ", shown, " needs a value"));
      }
    }
    std::string error;
    if (!flag->ParseFrom(value, &error)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "invalid value '", value, "' for flag ", shown,
          flag->IsOfType<absl::Duration>() ? " (expected a duration such as 30s, 2m)" : "", ": ",
          error));
    }
    parsed.flags_given.insert(name);
  }
  return parsed;
}

void PrintSubcommandHelp(const Subcommand& command, std::ostream& out) {
  out << "usage: neuralmesh " << command.usage << "\n\n"
      << (command.description.empty() ? command.summary : command.description) << "\n";
  if (command.flags.empty()) return;
  out << "\nflags:\n";
  for (const std::string& f : command.flags) {
    const absl::CommandLineFlag* flag = absl::FindCommandLineFlag(Canonical(f));
    if (flag == nullptr) continue;
    out << "  --" << f;
    if (f == "output") out << ", -o";
    const std::string def = flag->DefaultValue();
    out << "\n"
        << Wrap(absl::StrCat(flag->Help(), " (default: ", def.empty() ? "\"\"" : def, ")"), 84,
                "      ")
        << "\n";
  }
}

void PrintCommandList(const std::vector<Subcommand>& commands, std::ostream& out) {
  out << "usage: neuralmesh COMMAND [ARGS] [FLAGS]\n\n"
         "Neural Meshes surface reconstruction (Ivrissimtzis, Jeong, Seidel), locally or on a\n"
         "neuralmesh-server.\n\ncommands:\n";
  size_t width = 0;
  for (const Subcommand& c : commands) width = std::max(width, c.name.size());
  for (const Subcommand& c : commands) {
    out << "  " << c.name << std::string(width + 2 - c.name.size(), ' ') << c.summary << "\n";
  }
  out << "\nRun `neuralmesh COMMAND --help` for the flags of one command, `neuralmesh --version`\n"
         "for the version.\n";
}

int RunCommandLine(int argc, char** argv, const std::vector<Subcommand>& commands,
                   absl::string_view version,
                   std::ostream& out, std::ostream& err) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    PrintCommandList(commands, err);
    return 2;
  }
  if (args[0] == "--version" || args[0] == "version") {
    out << version << "\n";
    return 0;
  }
  if (IsHelp(args[0]) || args[0] == "help") {
    if (args.size() > 1) {
      if (const Subcommand* c = FindCommand(commands, args[1])) {
        PrintSubcommandHelp(*c, out);
        return 0;
      }
    }
    PrintCommandList(commands, out);
    return 0;
  }
  const Subcommand* command = FindCommand(commands, args[0]);
  if (command == nullptr) {
    err << "neuralmesh: unknown command '" << args[0] << "'\n\n";
    PrintCommandList(commands, err);
    return 2;
  }
  args.erase(args.begin());
  if (std::any_of(args.begin(), args.end(), IsHelp)) {
    PrintSubcommandHelp(*command, out);
    return 0;
  }
  absl::StatusOr<ParsedArgs> parsed = ParseSubcommandArgs(*command, args);
  if (!parsed.ok()) {
    err << "neuralmesh " << command->name << ": " << parsed.status().message() << "\n"
        << "usage: neuralmesh " << command->usage << "\n";
    return 2;
  }
  const absl::Status status = command->run(*parsed);
  if (!status.ok()) {
    err << "neuralmesh " << command->name << ": " << status.message() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace neuralmesh::client
