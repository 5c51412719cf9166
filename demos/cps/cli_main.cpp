// The cps command's commands assembled (run_command, command.h): list the scenes, simulate them
// headless, report, bench, and with the renderer render them to PNG frames and figures. Each
// command lives in its own file (see command.h); this file turns errors into exit codes. The
// executable (main.cpp) and the Python module's cps.command call it.
#include "command.h"
#include "options/diagnostics.h"
#include "options/options.h"
#include "output/output.h"
#include "scene.h"

#include <CLI/CLI.hpp>

#ifdef CPS_HAVE_RENDERER
#include "cps/render/renderer.h"
#endif

#include <iostream>
#include <string>
#include <vector>

namespace {

// `cps --version`: the build, and with the renderer each backend's context here (GL version and
// renderer: Mesa's and LLVM's versions for llvmpipe) or why it has none, and which one
// --backend auto takes.
std::string version_text() {
  std::string text = std::string("cps ") + cps::cli::engine_version();
#ifdef CPS_HAVE_RENDERER
  std::string chosen;
  for (const cps::render::Backend b : {cps::render::Backend::osmesa, cps::render::Backend::egl}) {
    const std::string name(cps::render::backend_name(b));
    try {
      cps::render::Renderer r(16, 16, b);
      text += "\nrenderer: " + r.context_description();
      if (chosen.empty()) chosen = name;
    } catch (const std::exception& e) {
      text += "\nrenderer: " + name + ": unavailable: " + e.what();
    }
  }
  text += "\n--backend auto: " + (chosen.empty() ? std::string("none (neither backend renders here)") : chosen);
#endif
  return text;
}

using namespace cps;

// What an unexpected argument of the command argv[1] is: the first word starting with '-' that
// the command has no option for, with the option nearest to it ("did you mean"), or CLI11's
// message `fallback` when every such word is known (a stray value).
std::string unknown_option_message(CLI::App& app, int argc, char** argv,
                                   const std::string& fallback) {
  const CLI::App* sub = nullptr;
  for (const CLI::App* s : app.get_subcommands({})) {
    if (argc > 1 && s->get_name() == argv[1]) sub = s;
  }
  if (sub == nullptr) return fallback;
  const std::string command = sub->get_name();
  for (int i = 2; i < argc; ++i) {
    std::string word = argv[i];
    if (word.size() < 2 || word[0] != '-') continue;
    word = word.substr(0, word.find('='));
    if (sub->get_option_no_throw(word) != nullptr) continue;
    if (sub->get_name() == "figure" && word == "--seconds") {
      return command + ": no --seconds: a figure takes its times from --times (s), e.g. "
                       "--times 0,0.5,2, and runs until the last of them";
    }
    std::vector<std::string> names;
    for (const CLI::Option* o : sub->get_options()) {
      for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    }
    return command + ": unknown option '" + word + "'; did you mean '" +
           scenes::nearest_name(word, names) + "'? Run 'cps " + command +
           " --help' for its options.";
  }
  return fallback + "\nRun 'cps --help' or 'cps COMMAND --help' for usage.";
}

// A clearer message for an option given without its value ("1 required TEXT missing") or with a
// value it cannot take ("Could not convert"): the option, what it wants (its description), and
// for a switch how to give it. `fallback`: CLI11's message, when the option cannot be found.
std::string value_message(CLI::App& app, int argc, char** argv, const CLI::ParseError& e,
                          const std::string& fallback) {
  const CLI::App* sub = nullptr;
  for (const CLI::App* s : app.get_subcommands({})) {
    if (argc > 1 && s->get_name() == argv[1]) sub = s;
  }
  const std::string what = e.what();
  const bool missing = dynamic_cast<const CLI::ArgumentMismatch*>(&e) != nullptr;
  // "--solver-error: 1 required TEXT missing"; "Could not convert: --rods = maybe".
  const std::size_t colon = what.find(": ");
  const std::size_t equals = what.find(" = ");
  if (colon == std::string::npos || (!missing && (equals == std::string::npos || equals < colon))) {
    return fallback;
  }
  const std::string name = missing ? what.substr(0, colon) : what.substr(colon + 2, equals - colon - 2);
  const CLI::Option* option = sub && name.rfind("--", 0) == 0 ? sub->get_option_no_throw(name) : nullptr;
  if (option == nullptr) return fallback;
  const std::string description = option->get_description();
  if (missing && option->get_expected_max() == 0) {  // a switch given twice
    std::string names;
    for (const std::string& n : option->get_lnames()) names += (names.empty() ? "--" : " or --") + n;
    return names + " given more than once: give one of them, once";
  }
  if (missing) {
    return name + " needs a value (" + option->get_type_name() + "): " + description;
  }
  const std::string value = what.substr(equals + 3);
  if (option->get_expected_max() == 0) {
    return name + " is a switch: give " + name + " alone (or " + name + "=true, " + name +
           "=false), not '" + value + "'";
  }
  return name + ": '" + value + "' is not a value it takes: " + description;
}

}  // namespace

namespace cps::cli {

int run_command(int argc, char** argv) {
  reset_diagnostics();
  clear_inputs();
  CLI::App app{"cps: the constraint based physics solver of Tamis & Maggiore (2015)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", version_text);
  std::vector<cli::Command> commands = {
      cli::add_list(app),
      cli::add_simulate(app, argc, argv),
      cli::add_report(app, argc, argv),
      cli::add_bench(app),
      cli::add_scene(app, argc, argv),
      cli::add_parameters(app),
#ifdef CPS_HAVE_RENDERER
      cli::add_render(app, argc, argv),
      cli::add_figure(app, argc, argv),
      cli::add_export(app, argc, argv),
      cli::add_diff(app, argc, argv),
#endif
  };

  std::string names;
  bool known = false;
  for (const CLI::App* sub : app.get_subcommands({})) {
    names += (names.empty() ? "" : ", ") + sub->get_name();
    known = known || (argc > 1 && sub->get_name() == argv[1]);
  }
  // cps itself takes only --help and --version before the command; CLI11 would report any other
  // flag there as "A subcommand is required", without naming it.
  if (argc > 1 && argv[1][0] == '-') {
    const std::string flag = argv[1];
    if (flag != "-h" && flag != "--help" && flag != "--version") {
      std::cerr << "cps: unknown option '" << flag
                << "'; before the command cps takes only --help and --version, and the commands "
                   "are: " << names << "\nRun 'cps --help' for usage.\n";
      return 2;
    }
  }
  if (argc > 1 && argv[1][0] != '-' && !known) {
    std::cerr << "cps: unknown command '" << argv[1] << "'; the commands are: " << names
              << "\nRun 'cps --help' for usage.\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ExtrasError& e) {
    std::cerr << "cps: " << unknown_option_message(app, argc, argv, e.what()) << "\n";
    return 2;
  } catch (const CLI::ArgumentMismatch& e) {
    std::cerr << "cps: " << value_message(app, argc, argv, e, e.what()) << "\n";
    return 2;
  } catch (const CLI::ConversionError& e) {
    std::cerr << "cps: " << value_message(app, argc, argv, e, e.what()) << "\n";
    return 2;
  } catch (const CLI::ParseError& e) {
    std::cerr << "cps: " << e.what() << "\nRun 'cps --help' or 'cps COMMAND --help' for usage.\n";
    return 2;
  }

  try {
    for (const cli::Command& command : commands) {
      if (*command.sub) return cli::exit_code_after_warnings(command.run());
    }
  } catch (const cli::UsageError& e) {
    cli::abandon_outputs();
    std::cerr << "cps: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    cli::abandon_outputs();
    std::cerr << "cps: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace cps::cli
