#include "scene/xml_source.h"

#include <algorithm>
#include <cstring>

namespace sylva::scene {

SourceFile::SourceFile(std::string path, std::string text)
    : path_(std::move(path)), text_(std::move(text)) {
  lineStarts_.push_back(0);
  for (size_t i = 0; i < text_.size(); ++i)
    if (text_[i] == '\n') lineStarts_.push_back(i + 1);
  // Default parsing (entities, end-of-line normalisation) on a copy that
  // pugixml owns; offsets stay those of the original text. No DOCTYPE is
  // expanded (pugixml never loads external entities).
  const pugi::xml_parse_result r =
      doc_.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
  ok_ = bool(r);
  if (!ok_) {
    const size_t at = r.offset < 0 ? 0 : size_t(r.offset);
    parseError_ = At(at, std::string("malformed XML: ") + r.description());
  }
}

SourceLoc SourceFile::Locate(size_t offset) const {
  offset = std::min(offset, text_.size());
  const auto it = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
  const size_t line = size_t(it - lineStarts_.begin());  // 1-based
  return SourceLoc{path_, int(line), int(offset - lineStarts_[line - 1]) + 1};
}

std::string_view SourceFile::Line(int line) const {
  if (line < 1 || size_t(line) > lineStarts_.size()) return {};
  const size_t start = lineStarts_[size_t(line) - 1];
  size_t end = size_t(line) < lineStarts_.size() ? lineStarts_[size_t(line)] - 1 : text_.size();
  if (end > start && text_[end - 1] == '\r') --end;
  return std::string_view(text_).substr(start, end - start);
}

size_t SourceFile::ElementOffset(const pugi::xml_node& node) const {
  const ptrdiff_t off = node.offset_debug();
  if (off < 0) return 0;
  size_t o = std::min(size_t(off), text_.size());
  // offset_debug points at the name; the diagnostic points at '<'.
  if (o > 0 && text_[o - 1] == '<') --o;
  return o;
}

SourceFile::AttrPos SourceFile::AttributeOffset(const pugi::xml_node& node,
                                                std::string_view name) const {
  AttrPos pos;
  size_t i = ElementOffset(node);
  if (i < text_.size() && text_[i] == '<') ++i;
  // Skip the element's name, then scan attributes until the tag ends.
  while (i < text_.size() && !std::strchr(" \t\r\n/>", text_[i])) ++i;
  while (i < text_.size()) {
    while (i < text_.size() && std::strchr(" \t\r\n", text_[i])) ++i;
    if (i >= text_.size() || text_[i] == '>' || text_[i] == '/') return pos;
    const size_t nameStart = i;
    while (i < text_.size() && !std::strchr(" \t\r\n=/>", text_[i])) ++i;
    const std::string_view found = std::string_view(text_).substr(nameStart, i - nameStart);
    while (i < text_.size() && std::strchr(" \t\r\n", text_[i])) ++i;
    if (i >= text_.size() || text_[i] != '=') return pos;
    ++i;
    while (i < text_.size() && std::strchr(" \t\r\n", text_[i])) ++i;
    if (i >= text_.size() || (text_[i] != '"' && text_[i] != '\'')) return pos;
    const char quote = text_[i++];
    const size_t valueStart = i;
    while (i < text_.size() && text_[i] != quote) ++i;
    if (found == name) return AttrPos{nameStart, valueStart};
    ++i;
  }
  return pos;
}

Diagnostic SourceFile::At(size_t offset, std::string message, int length, Severity severity) const {
  Diagnostic d = MakeError(Locate(offset), std::move(message), length);
  d.severity = severity;
  SetExcerpt(d, Line(d.loc.line));
  return d;
}

Diagnostic SourceFile::AtElement(const pugi::xml_node& node, std::string message) const {
  return At(ElementOffset(node), std::move(message), 1 + int(std::strlen(node.name())));
}

Diagnostic SourceFile::AtAttribute(const pugi::xml_node& node, std::string_view attr,
                                   std::string message) const {
  const AttrPos p = AttributeOffset(node, attr);
  if (p.name == std::string::npos) return AtElement(node, std::move(message));
  return At(p.name, std::move(message), int(attr.size()));
}

Diagnostic SourceFile::AtValue(const pugi::xml_node& node, std::string_view attr,
                               size_t byteInValue, std::string message, int length) const {
  const AttrPos p = AttributeOffset(node, attr);
  if (p.value == std::string::npos) return AtAttribute(node, attr, std::move(message));
  return At(p.value + byteInValue, std::move(message), std::max(1, length));
}

}  // namespace sylva::scene
