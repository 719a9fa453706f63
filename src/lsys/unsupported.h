// What Sylva reads but does not act on (yet): cpfg's turtle commands that
// draw nothing here, the environmental queries nobody answers, and
// parameter counts a turtle command does not use.
//
// The parser warns once per module name, at its first use, with the reason
// this file gives, so that a cpfg file is never drawn wrong without a word
// ("nothing is silently ignored"); `--strict` makes those warnings errors.
// The list of what the turtle does act on is docs/turtle.md; what cpfg has
// and Sylva has not is docs/cpfg.md.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace sylva::lsys {

// Why the module `name` (as lexed: `@Gs`, `?P`, `~leaf`, `F`) with `arity`
// parameters is not (fully) acted on, or nullopt when Sylva implements it
// or it is a plain module with no turtle action (letters, digits).
std::optional<std::string> UnsupportedModule(std::string_view name, int arity);

}  // namespace sylva::lsys
