#include "app/cli_help.h"

#include <cctype>
#include <vector>

#include "base/closest_name.h"
#include "base/terminal_text.h"

namespace selfcal::app {

namespace {

std::vector<std::string> SubcommandNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(sub->get_name());
  return names;
}

// The long option names ("--method") of `app` and the commands above it.
std::vector<std::string> LongOptionNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent()) {
    for (const CLI::Option* option : a->get_options()) {
      for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
    }
  }
  return names;
}

bool KnownOption(const CLI::App& app, const std::string& name) {
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent()) {
    if (a->get_option_no_throw(name) != nullptr) return true;
  }
  return false;
}

std::string CommandPath(const CLI::App& app) {
  std::string path;
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent()) {
    path = a->get_parent() == nullptr ? "selfcal" + path : " " + a->get_name() + path;
  }
  return path;
}

std::string UnknownCommand(const CLI::App& at, const std::string& word) {
  const std::vector<std::string> names = SubcommandNames(at);
  const std::string near = ClosestName(word, names);
  const std::string where = at.get_parent() == nullptr ? "selfcal: " : CommandPath(at) + ": ";
  std::string message = where + "unknown command `" + TerminalSafe(word) + "`";
  if (!near.empty()) return message + "; did you mean `" + near + "`?";
  message += "; the commands are:";
  for (const std::string& name : names) message += " " + name;
  return message;
}

}  // namespace

std::string UnknownNameMessage(const CLI::App& app, int argc, char** argv) {
  const CLI::App* at = &app;
  bool subcommand_chosen = false;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    const bool looks_like_option = word.size() > 1 && word[0] == '-' && !std::isdigit(static_cast<unsigned char>(word[1])) &&
                                   word[1] != '.';
    if (looks_like_option) {
      const std::string name = word.substr(0, word.find('='));
      if (name.rfind("--", 0) != 0 || KnownOption(*at, name)) continue;  // short options: CLI11 says it
      const std::string near = ClosestName(name.substr(2), [&] {
        std::vector<std::string> bare;
        for (const std::string& n : LongOptionNames(*at)) bare.push_back(n.substr(2));
        return bare;
      }());
      std::string message = CommandPath(*at) + ": unknown option `" + TerminalSafe(name) + "`";
      return near.empty() ? message + " (" + CommandPath(*at) + " --help lists the options)"
                          : message + "; did you mean `--" + near + "`?";
    }
    // A word that is not an option: a subcommand while this command has some and none is chosen yet,
    // else a value or a positional argument.
    if (subcommand_chosen || SubcommandNames(*at).empty()) continue;
    const CLI::App* sub = nullptr;
    for (const CLI::App* candidate : at->get_subcommands([](const CLI::App*) { return true; })) {
      if (candidate->check_name(word)) sub = candidate;
    }
    if (sub == nullptr) return UnknownCommand(*at, word);
    at = sub;
    subcommand_chosen = SubcommandNames(*at).empty();
  }
  return "";
}

}  // namespace selfcal::app
