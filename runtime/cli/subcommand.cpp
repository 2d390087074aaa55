#include "subcommand.hpp"

#include <iostream>

#include "animrt/core/error.hpp"

namespace animrt::cli {

void set_subcommand_body(CLI::App* cmd, std::function<int()> body) {
  cmd->callback([body = std::move(body)] {
    int code = 0;
    try {
      code = body();
    } catch (const InputError& e) {
      std::cerr << "error: " << e.what() << '\n';
      code = kExitInvalidInput;
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << '\n';
      code = kExitUsage;
    }
    if (code != 0) throw CLI::RuntimeError(code);
    throw CLI::Success();
  });
}

void hide_empty_defaults(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_default_str() == "[]" || option->get_required()) option->default_str("");
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    hide_empty_defaults(*sub);
  }
}

}  // namespace animrt::cli
