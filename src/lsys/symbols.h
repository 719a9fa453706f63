// SymbolTable: module names as small integer ids.
//
// A symbol is a (name, parameter count) pair: `F` and `F(l)` are different
// symbols, so a module's arity is a table lookup and a word need not store
// it. Ids are 16-bit (at most 65,535 symbols in a grammar). The brackets
// `[` `]` always have ids 0 and 1.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace sylva::lsys {

using SymbolId = uint16_t;

inline constexpr SymbolId kOpenBracket = 0;   // "["
inline constexpr SymbolId kCloseBracket = 1;  // "]"
inline constexpr int kMaxSymbols = 65535;
inline constexpr int kMaxArity = 64;  // parameters per module

class SymbolTable {
 public:
  SymbolTable();

  // Returns the id of (name, arity), adding it when new; nullopt when the
  // table is full.
  std::optional<SymbolId> Intern(std::string_view name, int arity);
  std::optional<SymbolId> Find(std::string_view name, int arity) const;

  size_t size() const { return names_.size(); }
  const std::string& name(SymbolId id) const { return names_[id]; }
  int arity(SymbolId id) const { return arities_[id]; }
  // Arity of every symbol, indexed by id (hot: used per module).
  const std::vector<uint8_t>& arities() const { return arities_; }

 private:
  std::vector<std::string> names_;
  std::vector<uint8_t> arities_;
  std::unordered_map<std::string, SymbolId> index_;  // key: name + '\x01' + arity
};

}  // namespace sylva::lsys
