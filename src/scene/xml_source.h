// One scene file as read: its text, its parsed XML (pugixml), and the map
// from byte offsets to line and column that every diagnostic needs.
//
// pugixml reports where an element starts (xml_node::offset_debug) but not
// where its attributes are; AttributeOffset finds an attribute's name and
// value in the element's start tag, so an error about a value points at
// the value itself.
#pragma once

#include <pugixml.hpp>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostic.h"

namespace sylva::scene {

class SourceFile {
 public:
  // Parses `text`; a malformed document is reported through `error`
  // (file:line:col of pugixml's offset) and ok() is false.
  SourceFile(std::string path, std::string text);
  SourceFile(const SourceFile&) = delete;
  SourceFile& operator=(const SourceFile&) = delete;

  bool ok() const { return ok_; }
  const Diagnostic& parseError() const { return parseError_; }
  const std::string& path() const { return path_; }
  const pugi::xml_document& doc() const { return doc_; }

  // 1-based line and byte column of a byte offset (clamped to the text).
  SourceLoc Locate(size_t offset) const;
  // The text of a 1-based line, without its newline.
  std::string_view Line(int line) const;

  // Offset of an element's '<' (or of its name when '<' is not found).
  size_t ElementOffset(const pugi::xml_node& node) const;
  // Offset of the attribute's name and of the first byte of its value in
  // the element's start tag; npos when not found.
  struct AttrPos {
    size_t name = std::string::npos, value = std::string::npos;
  };
  AttrPos AttributeOffset(const pugi::xml_node& node, std::string_view name) const;

  // An error (or warning) at a byte offset, with the line as excerpt.
  Diagnostic At(size_t offset, std::string message, int length = 1,
                Severity severity = Severity::kError) const;
  Diagnostic AtElement(const pugi::xml_node& node, std::string message) const;
  Diagnostic AtAttribute(const pugi::xml_node& node, std::string_view attr,
                         std::string message) const;
  // At a byte inside an attribute's value (0: its first byte).
  Diagnostic AtValue(const pugi::xml_node& node, std::string_view attr, size_t byteInValue,
                     std::string message, int length = 1) const;

 private:
  std::string path_, text_;
  std::vector<size_t> lineStarts_;
  pugi::xml_document doc_;
  bool ok_ = false;
  Diagnostic parseError_;
};

}  // namespace sylva::scene
