#include "app/output_options.h"

#include <sys/stat.h>

#include <map>
#include <memory>

#include "app/cli_util.h"

namespace selfcal::app {

namespace {

struct RegisteredOutput {
  std::string name;
  std::string* path;
  OutputKind kind;
  std::vector<std::string> files;
  std::function<std::string()> when_empty{};
};

struct CommandOutputs {
  std::vector<RegisteredOutput> outputs;
  std::unique_ptr<bool> force;  // --force, registered with the first file or directory output
  std::vector<std::function<std::vector<std::string>()>> inputs{};  // AddInputPaths
};

// Keyed by the command's CLI11 app, which outlives every use (RunCommandLine's app).
std::map<const CLI::App*, CommandOutputs>& Registry() {
  static std::map<const CLI::App*, CommandOutputs> registry;
  return registry;
}

bool TakesForce(OutputKind kind) {
  return kind == OutputKind::kFile || kind == OutputKind::kFileAndParents || kind == OutputKind::kDirectory;
}

bool ExistingFile(const std::string& path) {
  struct stat info {};
  return !path.empty() && ::stat(path.c_str(), &info) == 0 && !S_ISDIR(info.st_mode);
}

// The values of `cmd`'s options other than its written outputs and `self` (given, else their defaults) that
// name an existing file, as given and as ResolveDataPath finds them: what the command reads. An updated
// input (kUpdatedFile) is an input of the other outputs.
std::vector<std::string> InputsOf(const CLI::App& cmd, const CommandOutputs& outputs, const RegisteredOutput& self) {
  std::vector<std::string> inputs;
  for (const CLI::Option* option : cmd.get_options()) {
    if (option->get_type_size_max() == 0 || option->check_name(self.name)) continue;  // a flag, or self
    bool written = false;
    for (const RegisteredOutput& output : outputs.outputs) {
      written = written || (option->check_name(output.name) && output.kind != OutputKind::kUpdatedFile);
    }
    if (written) continue;
    std::vector<std::string> values = option->results();
    if (values.empty() && !option->get_default_str().empty()) values.push_back(option->get_default_str());
    for (const std::string& value : values) {
      for (const std::string& path : {value, ResolveDataPath(value)}) {
        if (ExistingFile(path)) inputs.push_back(path);
      }
    }
  }
  for (const auto& more : outputs.inputs) {
    for (const std::string& path : more()) {
      if (ExistingFile(path)) inputs.push_back(path);
    }
  }
  return inputs;
}

}  // namespace

CLI::Option* AddOutputOption(CLI::App* cmd, const std::string& name, std::string* path, OutputKind kind,
                             const std::string& help, std::vector<std::string> files) {
  CommandOutputs& outputs = Registry()[cmd];
  if (TakesForce(kind) && !outputs.force) {
    outputs.force = std::make_unique<bool>(false);
    cmd->add_flag("--force", *outputs.force,
                  "Replace output files that exist already (never inside a session directory, never an input)");
  }
  outputs.outputs.push_back({name, path, kind, std::move(files)});
  return cmd->add_option(name, *path, help);
}

void SetOutputPathWhenEmpty(CLI::App* cmd, const std::string& name, std::function<std::string()> path) {
  for (RegisteredOutput& output : Registry()[cmd].outputs) {
    if (output.name == name) output.when_empty = path;
  }
}

void AddInputPaths(CLI::App* cmd, std::function<std::vector<std::string>()> inputs) {
  Registry()[cmd].inputs.push_back(std::move(inputs));
}

Status CheckOutputOptions(const CLI::App& cmd) {
  const auto found = Registry().find(&cmd);
  if (found != Registry().end()) {
    const CommandOutputs& outputs = found->second;
    const bool force = outputs.force && *outputs.force;
    for (const RegisteredOutput& output : outputs.outputs) {
      std::string path = *output.path;
      if (path.empty() && output.when_empty) path = output.when_empty();
      const session::OutputPath checked{output.name, path, output.kind, output.files};
      if (Status s = session::CheckOutputPath(checked, InputsOf(cmd, outputs, output), force); !s.ok()) return s;
    }
  }
  for (const CLI::App* sub : cmd.get_subcommands()) {
    if (Status s = CheckOutputOptions(*sub); !s.ok()) return s;
  }
  return Status::Ok();
}

void ListOutputOptions(const CLI::App& app, std::ostream& out) {
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    const std::string name = (app.get_parent() == nullptr ? "" : app.get_name() + " ") + sub->get_name();
    const auto found = Registry().find(sub);
    if (found != Registry().end()) {
      for (const RegisteredOutput& output : found->second.outputs) {
        out << name << "\t" << output.name << "\t" << session::OutputKindName(output.kind) << "\n";
      }
    }
    ListOutputOptions(*sub, out);
  }
}

}  // namespace selfcal::app
