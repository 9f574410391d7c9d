// `tempera rigid`, the rigid-body method's command before the registry ran
// every method through `tempera stylize --method`: kept so that a script
// still calling it learns the new form (exit 2). Not listed in --help.
#include "cli_args.hpp"
#include "commands.hpp"
#include "tempera/engine/error.hpp"

namespace tempera::cli {
namespace {

int run_moved_rigid(const Args&) {
  throw ValueError(
      "'tempera rigid' is now 'tempera stylize --method rigid --guides CACHE --frames A-B --out OUT' "
      "(--cache is --guides; the frames go to OUT/frames; see tempera stylize --method rigid --help)");
}

const CommandRegistration kCommand("rigid", "", run_moved_rigid);

}  // namespace
}  // namespace tempera::cli
