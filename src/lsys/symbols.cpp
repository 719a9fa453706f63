#include "lsys/symbols.h"

namespace sylva::lsys {

static std::string Key(std::string_view name, int arity) {
  std::string k(name);
  k += '\x01';
  k += std::to_string(arity);
  return k;
}

SymbolTable::SymbolTable() {
  Intern("[", 0);
  Intern("]", 0);
}

std::optional<SymbolId> SymbolTable::Intern(std::string_view name, int arity) {
  std::string k = Key(name, arity);
  auto it = index_.find(k);
  if (it != index_.end()) return it->second;
  if (names_.size() >= size_t(kMaxSymbols)) return std::nullopt;
  SymbolId id = SymbolId(names_.size());
  names_.emplace_back(name);
  arities_.push_back(uint8_t(arity));
  index_.emplace(std::move(k), id);
  return id;
}

std::optional<SymbolId> SymbolTable::Find(std::string_view name, int arity) const {
  auto it = index_.find(Key(name, arity));
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

}  // namespace sylva::lsys
