// The scene reader: XML (pugixml) to the scene model, in four passes:
//  1. load the root file and its includes, depth first, splicing the
//     children of each included <scene> where its <include> stood;
//  2. parameters: every <default>, then the -D overrides;
//  3. ids: every element's id, unique, `ground` reserved;
//  4. the elements, each read by the function for its name. An attribute
//     reader (Attrs) records every name it is asked for; what the element
//     holds beyond those is an unknown attribute, reported with the closest
//     known name. References (`with`, `on`, `of`, `emit`, `avoid`, <ref>)
//     are checked against the ids of pass 3 and the kinds each may name.
// Finally the declared sizes are summed against the memory budget.
#include "scene/reader.h"

#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "core/atomic_file.h"
#include "core/spelling.h"
#include "scene/build.h"
#include "scene/values.h"
#include "scene/xml_source.h"
#include "terrain/height_field.h"

namespace sylva::scene {

std::string FolderOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

namespace {

struct Elem {
  pugi::xml_node node;
  const SourceFile* file = nullptr;
  std::string_view name() const { return node.name(); }
};

std::string Q(std::string_view s) {
  return "'" + std::string(s) + "'";
}

// A numeric range for Attrs::Number; bounds are inclusive unless open.
struct Range {
  double min = -HUGE_VAL, max = HUGE_VAL;
  bool minOpen = false, maxOpen = false;
  std::string Describe() const {
    auto num = [](double v) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", v);
      return std::string(buf);
    };
    if (min == 0 && minOpen && max == HUGE_VAL) return "greater than 0";
    if (min == 0 && !minOpen && max == HUGE_VAL) return "0 or more";
    if (max == HUGE_VAL) return (minOpen ? "greater than " : "at least ") + num(min);
    return "between " + num(min) + " and " + num(max);
  }
  bool Contains(double v) const {
    return (minOpen ? v > min : v >= min) && (maxOpen ? v < max : v <= max);
  }
};
const Range kAny{};
const Range kPositive{0, HUGE_VAL, true};
const Range kNonNegative{0, HUGE_VAL};
Range Between(double a, double b) {
  return Range{a, b};
}

// Largest count any attribute takes: beyond it sizes overflow estimates.
constexpr uint64_t kMaxCount = uint64_t(1) << 40;
// The renderer's shaders take this many lights (draw::kMaxLights).
constexpr size_t kMaxLights = 8;

class Reader;

// Reads one element's attributes; see the file comment.
class Attrs {
 public:
  // takesId: the element may carry an `id` (not <scene> or <include>).
  Attrs(Reader& r, Elem e, bool takesId = true);
  ~Attrs() { Finish(); }

  bool Has(std::string_view name) {
    Know(name);
    return bool(e_.node.attribute(std::string(name).c_str()));
  }
  // The value after `$name` substitution; nullopt when absent or bad.
  std::optional<std::string> Text(std::string_view name);
  bool Number(std::string_view name, double& out, const Range& range = kAny);
  template <typename Int>
  bool Count(std::string_view name, Int& out, uint64_t min, uint64_t max);
  bool Vector(std::string_view name, Vec3& out, bool nonZero = false);
  bool Numbers(std::string_view name, std::vector<double>& out, size_t n);
  bool Color(std::string_view name, Vec3& out);
  bool Bool(std::string_view name, bool& out);
  template <typename E>
  bool Enum(std::string_view name, E& out,
            const std::vector<std::pair<std::string_view, E>>& choices);
  // Ids that must name elements of the given kinds (or `ground` when
  // allowGround).
  bool Refs(std::string_view name, std::vector<std::string>& out,
            const std::vector<std::string_view>& kinds, bool allowGround, SourceLoc* loc = nullptr);
  bool Ref(std::string_view name, std::string& out, const std::vector<std::string_view>& kinds,
           bool allowGround = false);
  // A file path, resolved against the folder of the file it is written in.
  bool Path(std::string_view name, std::string& out, SourceLoc* loc = nullptr);

  void Error(std::string_view attr, std::string message);
  void ValueError(std::string_view attr, const scene::ValueError& e);
  SourceLoc Loc() const { return e_.file->Locate(e_.file->ElementOffset(e_.node)); }
  void Finish();

 private:
  void Know(std::string_view name) {
    if (std::find(known_.begin(), known_.end(), name) == known_.end()) known_.push_back(name);
  }
  Reader& r_;
  Elem e_;
  std::vector<std::string_view> known_;
  std::set<std::string> substituted_;  // attributes whose value used $params
  bool finished_ = false;
};

class Reader {
 public:
  explicit Reader(const ReadOptions& o) : options_(o) {}

  ReadResult Run(const std::string& path);

  DiagnosticList diags;
  std::map<std::string, std::string> params;
  std::map<std::string, Elem> ids;

  void Add(Diagnostic d) { diags.Add(std::move(d)); }

 private:
  bool Load(const std::string& path, int depth, std::vector<std::string>& chain, const Elem* from,
            std::vector<Elem>& out);
  void ReadRootAttributes(const Elem& root);
  void CollectDefaults();
  void CollectIds(const Elem& top);
  void CollectId(const Elem& e);
  static constexpr int kMaxNesting = 3;
  bool badNesting_ = false;
  void ReadTop(const Elem& e);
  void CheckMemory();

  CameraDef ReadCamera(const Elem& e);
  LightDef ReadLight(const Elem& e);
  SkyDef ReadSky(const Elem& e);
  TerrainDef ReadTerrain(const Elem& e);
  PlantDef ReadPlant(const Elem& e);
  ForestDef ReadForest(const Elem& e);
  ParticlesDef ReadParticles(const Elem& e);
  ClothDef ReadCloth(const Elem& e);
  FlockDef ReadFlock(const Elem& e);
  WindDef ReadWind(const Elem& e);
  SimulationDef ReadSimulation(const Elem& e);
  std::vector<Define> ReadDefines(const Elem& e);
  EmitterDef ReadEmitter(const Elem& e);
  ForceDef ReadForce(const Elem& e);
  CollideDef ReadCollide(const Elem& e);
  SpringsDef ReadSprings(const Elem& e);
  OnDeathDef ReadOnDeath(const Elem& e);
  DrawDef ReadDraw(const Elem& e);
  // Calls `fn` for each child element (a <ref> replaced by its target),
  // reporting text, unknown children and refs to the wrong kind.
  template <typename Fn>
  void Children(const Elem& parent, const std::vector<std::string_view>& allowed, Fn fn);
  void NoChildren(const Elem& e) {
    Children(e, {}, [](const Elem&) {});
  }

  const ReadOptions& options_;
  std::vector<std::unique_ptr<SourceFile>> files_;
  std::vector<Elem> top_;  // the root's children, includes spliced
  Elem root_;
  size_t bytesRead_ = 0;
  Scene scene_;
  std::map<std::string, SourceLoc> singletons_;
  // A declared size, at the attribute that declares it (the element when
  // the attribute is absent and its default is counted).
  struct Size {
    uint64_t bytes;
    Diagnostic at;
    std::string what;
  };
  std::vector<Size> sizes_;
  void AddSize(const Elem& e, const char* attr, uint64_t bytes, std::string what) {
    const pugi::xml_attribute a = e.node.attribute(attr);
    const int length = a ? std::max(1, int(std::strlen(a.value()))) : 1;
    sizes_.push_back({bytes, e.file->AtValue(e.node, attr, 0, {}, length), std::move(what)});
  }
};

// ---------------------------------------------------------------------------
// Attrs

Attrs::Attrs(Reader& r, Elem e, bool takesId) : r_(r), e_(e) {
  if (takesId) Know("id");
}

void Attrs::Error(std::string_view attr, std::string message) {
  r_.Add(e_.file->AtAttribute(e_.node, attr, std::move(message)));
}

void Attrs::ValueError(std::string_view attr, const scene::ValueError& e) {
  std::string message = Q(attr) + ": " + e.message;
  if (substituted_.count(std::string(attr))) {
    message += " (after parameter substitution)";
    r_.Add(e_.file->AtValue(e_.node, attr, 0, std::move(message)));
    return;
  }
  r_.Add(e_.file->AtValue(e_.node, attr, e.at, std::move(message), e.length));
}

std::optional<std::string> Attrs::Text(std::string_view name) {
  Know(name);
  const pugi::xml_attribute a = e_.node.attribute(std::string(name).c_str());
  if (!a) return std::nullopt;
  const std::string raw = a.value();
  if (raw.find('$') == std::string::npos) return raw;
  // $name: a parameter; the name runs over letters, digits and '_'.
  std::string out;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] != '$') {
      out += raw[i];
      continue;
    }
    size_t j = i + 1;
    while (j < raw.size() && (std::isalnum(static_cast<unsigned char>(raw[j])) || raw[j] == '_'))
      ++j;
    const std::string param = raw.substr(i + 1, j - i - 1);
    if (param.empty()) {
      r_.Add(e_.file->AtValue(e_.node, name, i,
                              Q(name) + ": '$' must be followed by a parameter name"));
      return std::nullopt;
    }
    const auto it = r_.params.find(param);
    if (it == r_.params.end()) {
      std::vector<std::string_view> known;
      for (const auto& [k, v] : r_.params) known.push_back(k);
      r_.Add(e_.file->AtValue(e_.node, name, i,
                              "unknown parameter '$" + param + "'" + DidYouMean(param, known) +
                                  "; declare it with <default name=\"" + param +
                                  "\" value=\"...\"/>",
                              int(j - i)));
      return std::nullopt;
    }
    out += it->second;
    i = j - 1;
  }
  substituted_.insert(std::string(name));
  return out;
}

bool Attrs::Number(std::string_view name, double& out, const Range& range) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<double> p = ParseNumber(*t);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  if (!range.Contains(*p.value)) {
    ValueError(name, {"must be " + range.Describe() + ", found " + *t, 0, int(t->size())});
    return false;
  }
  out = *p.value;
  return true;
}

template <typename Int>
bool Attrs::Count(std::string_view name, Int& out, uint64_t min, uint64_t max) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<uint64_t> p = ParseCount(*t, max);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  if (*p.value < min) {
    ValueError(name,
               {"must be at least " + std::to_string(min) + ", found " + *t, 0, int(t->size())});
    return false;
  }
  out = Int(*p.value);
  return true;
}

bool Attrs::Vector(std::string_view name, Vec3& out, bool nonZero) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<Vec3> p = ParseVec3(*t);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  if (nonZero && p.value->norm() == 0) {
    ValueError(name, {"must not be the zero vector", 0, int(t->size())});
    return false;
  }
  out = *p.value;
  return true;
}

bool Attrs::Numbers(std::string_view name, std::vector<double>& out, size_t n) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<std::vector<double>> p = ParseNumbers(*t, n);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  out = *p.value;
  return true;
}

bool Attrs::Color(std::string_view name, Vec3& out) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<Vec3> p = ParseColor(*t);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  out = *p.value;
  return true;
}

bool Attrs::Bool(std::string_view name, bool& out) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<bool> p = ParseBool(*t);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  out = *p.value;
  return true;
}

template <typename E>
bool Attrs::Enum(std::string_view name, E& out,
                 const std::vector<std::pair<std::string_view, E>>& choices) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  std::vector<std::string_view> names;
  for (const auto& [n, v] : choices) {
    if (n == *t) {
      out = v;
      return true;
    }
    names.push_back(n);
  }
  std::string list;
  for (std::string_view n : names) list += (list.empty() ? "" : ", ") + std::string(n);
  ValueError(name, {"unknown value " + Q(*t) + DidYouMean(*t, names) + "; one of: " + list, 0,
                    int(t->size())});
  return false;
}

bool Attrs::Refs(std::string_view name, std::vector<std::string>& out,
                 const std::vector<std::string_view>& kinds, bool allowGround, SourceLoc* loc) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  const Parsed<std::vector<std::string>> p = ParseNames(*t);
  if (!p.ok()) {
    ValueError(name, p.error);
    return false;
  }
  if (loc) {
    const auto pos = e_.file->AttributeOffset(e_.node, name);
    *loc = e_.file->Locate(pos.value == std::string::npos ? 0 : pos.value);
  }
  std::string kindList;
  for (std::string_view k : kinds) kindList += (kindList.empty() ? "<" : ">, <") + std::string(k);
  kindList += ">";
  if (allowGround) kindList += " or 'ground'";
  bool ok = true;
  for (const std::string& id : *p.value) {
    const size_t at = t->find(id);
    if (id == "ground" && allowGround) continue;
    const auto it = r_.ids.find(id);
    if (it == r_.ids.end()) {
      std::vector<std::string_view> known;
      for (const auto& [k, e] : r_.ids)
        if (std::find(kinds.begin(), kinds.end(), e.name()) != kinds.end()) known.push_back(k);
      if (allowGround) known.push_back("ground");
      ValueError(name, {"no element has the id " + Q(id) + DidYouMean(id, known) +
                            "; expected the id of " + kindList,
                        at, int(id.size())});
      ok = false;
      continue;
    }
    if (std::find(kinds.begin(), kinds.end(), it->second.name()) == kinds.end()) {
      ValueError(name, {Q(id) + " is a <" + std::string(it->second.name()) + ">; " + Q(name) +
                            " takes the id of " + kindList,
                        at, int(id.size())});
      ok = false;
    }
  }
  if (ok) out = *p.value;
  return ok;
}

bool Attrs::Ref(std::string_view name, std::string& out, const std::vector<std::string_view>& kinds,
                bool allowGround) {
  std::vector<std::string> ids;
  if (!Refs(name, ids, kinds, allowGround)) return false;
  if (ids.size() != 1) {
    Error(name, Q(name) + " takes one id, found " + std::to_string(ids.size()));
    return false;
  }
  out = ids[0];
  return true;
}

bool Attrs::Path(std::string_view name, std::string& out, SourceLoc* loc) {
  const std::optional<std::string> t = Text(name);
  if (!t) return false;
  if (t->empty() || t->find('\0') != std::string::npos) {
    ValueError(name, {"expected a file name", 0});
    return false;
  }
  if (loc) {
    const auto pos = e_.file->AttributeOffset(e_.node, name);
    *loc = e_.file->Locate(pos.value == std::string::npos ? 0 : pos.value);
  }
  out = (*t)[0] == '/' ? *t : FolderOf(e_.file->path()) + *t;
  return true;
}

void Attrs::Finish() {
  if (finished_) return;
  finished_ = true;
  for (const pugi::xml_attribute a : e_.node.attributes()) {
    const std::string_view n = a.name();
    if (std::find(known_.begin(), known_.end(), n) != known_.end()) continue;
    std::string list;
    for (std::string_view k : known_) list += (list.empty() ? "" : ", ") + std::string(k);
    r_.Add(e_.file->AtAttribute(e_.node, n,
                                "unknown attribute " + Q(n) + " on <" + std::string(e_.name()) +
                                    ">" + DidYouMean(n, known_) + "; it takes: " + list));
  }
}

// ---------------------------------------------------------------------------
// Loading and includes

bool Reader::Load(const std::string& path, int depth, std::vector<std::string>& chain,
                  const Elem* from, std::vector<Elem>& out) {
  auto fail = [&](std::string message) {
    if (from)
      Add(from->file->AtAttribute(from->node, "file", std::move(message)));
    else
      Add(MakeError(SourceLoc{path, 0, 0}, std::move(message)));
    return false;
  };
  if (files_.size() >= kMaxSceneFiles)
    return fail("a scene may read at most " + std::to_string(kMaxSceneFiles) + " files");
  // A cycle is found on the resolved path, so "a.xml" and "./a.xml" meet.
  char* real = realpath(path.c_str(), nullptr);
  const std::string key = real ? std::string(real) : path;
  std::free(real);
  if (std::find(chain.begin(), chain.end(), key) != chain.end()) {
    std::string names;
    for (const std::string& c : chain) names += c + " -> ";
    return fail("include cycle: " + names + key);
  }
  Expected<std::string> text = options_.readFile ? options_.readFile(path) : ReadFile(path);
  if (!text)
    return fail(from ? "cannot include '" + path + "': " + text.error().message
                     : text.error().message);
  bytesRead_ += text->size();
  if (bytesRead_ > kMaxSceneBytes)
    return fail("a scene may read at most " + std::to_string(kMaxSceneBytes >> 20) +
                " MiB of files in all");
  files_.push_back(std::make_unique<SourceFile>(path, std::move(*text)));
  const SourceFile& f = *files_.back();
  scene_.files.push_back(path);
  if (!f.ok()) {
    Add(f.parseError());
    return false;
  }
  // One root element, <scene>.
  pugi::xml_node root;
  for (pugi::xml_node n : f.doc().children()) {
    if (n.type() != pugi::node_element) continue;
    if (root) {
      Add(f.AtElement(n, "a scene file has one root element, <scene>"));
      return false;
    }
    root = n;
  }
  if (!root) {
    Add(MakeError(SourceLoc{path, 1, 1}, "no <scene> element in the file"));
    return false;
  }
  if (std::string_view(root.name()) != "scene") {
    Add(f.AtElement(root, "the root element must be <scene>, found <" + std::string(root.name()) +
                              ">" + DidYouMean(root.name(), {"scene"})));
    return false;
  }
  const Elem rootElem{root, &f};
  if (!from) root_ = rootElem;
  if (from) {
    // An included file's <scene> may carry only its version.
    Attrs a(*this, rootElem, false);
    int version = 1;
    if (a.Count("version", version, 1, 1000) && version != 1)
      a.Error("version", "this Sylva reads scene version 1, found " + std::to_string(version));
  }
  chain.push_back(key);
  bool ok = true;
  for (pugi::xml_node n : root.children()) {
    if (n.type() == pugi::node_pcdata || n.type() == pugi::node_cdata) {
      const std::string_view v = n.value();
      if (v.find_first_not_of(" \t\r\n") != std::string_view::npos) {
        Add(f.AtElement(root, "text inside <scene>; only elements belong there"));
        ok = false;
      }
      continue;
    }
    if (n.type() != pugi::node_element) continue;
    const Elem e{n, &f};
    if (e.name() != "include") {
      out.push_back(e);
      continue;
    }
    Attrs a(*this, e, false);
    std::string file;
    if (!a.Has("file")) {
      Add(f.AtElement(n, "<include> needs a 'file' attribute"));
      ok = false;
      continue;
    }
    // Parameters are not known yet when includes are spliced: a file name
    // is literal.
    const std::string raw = n.attribute("file").value();
    if (raw.find('$') != std::string::npos) {
      a.Error("file", "an include's file name cannot use $parameters");
      ok = false;
      continue;
    }
    if (!a.Path("file", file)) {
      ok = false;
      continue;
    }
    if (depth + 1 > kMaxIncludeDepth) {
      a.Error("file", "includes nest deeper than " + std::to_string(kMaxIncludeDepth) +
                          " levels (the root file is level 0)");
      ok = false;
      continue;
    }
    if (!Load(file, depth + 1, chain, &e, out)) ok = false;
  }
  chain.pop_back();
  return ok;
}

void Reader::ReadRootAttributes(const Elem& root) {
  Attrs a(*this, root, false);
  int version = 1;
  if (!a.Has("version"))
    Add(root.file->AtElement(root.node, "<scene> needs version=\"1\""));
  else if (a.Count("version", version, 1, 1000) && version != 1)
    a.Error("version", "this Sylva reads scene version 1, found " + std::to_string(version));
  scene_.version = version;
  a.Count("seed", scene_.seed, 0, uint64_t(1) << 53);
}

void Reader::CollectDefaults() {
  std::map<std::string, SourceLoc> where;
  for (const Elem& e : top_) {
    if (e.name() != "default") continue;
    Attrs a(*this, e);
    const bool named = a.Has("name"), valued = a.Has("value");
    if (std::string_view(e.node.attribute("value").value()).find('$') != std::string_view::npos ||
        std::string_view(e.node.attribute("name").value()).find('$') != std::string_view::npos) {
      Add(e.file->AtElement(e.node,
                            "a <default> is literal: its name and value cannot use "
                            "$parameters"));
      continue;
    }
    const std::optional<std::string> name = a.Text("name");
    const std::optional<std::string> value = a.Text("value");
    if (!named || !valued) {
      Add(e.file->AtElement(e.node, "<default> needs 'name' and 'value'"));
      continue;
    }
    if (!name || !value) continue;
    bool valid = !name->empty() && !std::isdigit(static_cast<unsigned char>((*name)[0]));
    for (char c : *name) valid = valid && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
    if (!valid) {
      a.Error("name", "a parameter name is letters, digits and '_', not starting with a digit");
      continue;
    }
    const auto [it, fresh] = where.emplace(*name, a.Loc());
    if (!fresh) {
      a.Error("name", "parameter " + Q(*name) + " is declared twice (first at " + it->second.file +
                          ":" + std::to_string(it->second.line) + ")");
      continue;
    }
    params[*name] = *value;
    NoChildren(e);
  }
  for (const std::string& d : options_.defines) {
    const size_t eq = d.find('=');
    const std::string name = d.substr(0, eq);
    if (eq == std::string::npos || name.empty()) {
      Add(MakeError(SourceLoc{}, "-D " + Q(d) + ": expected NAME=VALUE"));
      continue;
    }
    if (!params.count(name)) {
      std::vector<std::string_view> known;
      for (const auto& [k, v] : params) known.push_back(k);
      Add(MakeError(SourceLoc{}, "-D " + name + ": the scene declares no parameter " + Q(name) +
                                     DidYouMean(name, known) +
                                     " (declare it with <default name=\"" + name +
                                     "\" value=\"...\"/>)"));
      continue;
    }
    params[name] = d.substr(eq + 1);
  }
  scene_.parameters = params;
}

void Reader::CollectIds(const Elem& top) {
  // Iterative: a hostile file may nest a million elements. Scene elements
  // nest three deep at most (<particles><emitter>), so deeper nesting is an
  // error here, before any recursive reader sees it.
  std::vector<std::pair<Elem, int>> stack = {{top, 1}};
  while (!stack.empty()) {
    const auto [e, depth] = stack.back();
    stack.pop_back();
    if (depth > kMaxNesting) {
      Add(e.file->AtElement(e.node, "elements nest deeper than any scene element can (" +
                                        std::to_string(kMaxNesting) + " levels below <scene>)"));
      badNesting_ = true;
      continue;
    }
    CollectId(e);
    for (pugi::xml_node c = e.node.last_child(); c; c = c.previous_sibling())
      if (c.type() == pugi::node_element) stack.push_back({Elem{c, e.file}, depth + 1});
  }
}

void Reader::CollectId(const Elem& e) {
  if (e.name() == "ref") return;
  const pugi::xml_attribute a = e.node.attribute("id");
  if (!a) return;
  if (e.name() == "default") {
    Add(e.file->AtAttribute(
        e.node, "id",
        "<" + std::string(e.name()) + "> has no 'id': nothing can refer to it (it has a 'name')"));
    return;
  }
  const std::string id = a.value();
  bool valid = !id.empty() && (std::isalpha(static_cast<unsigned char>(id[0])) || id[0] == '_');
  for (char c : id)
    valid =
        valid && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.');
  if (!valid) {
    Add(e.file->AtValue(e.node, "id", 0,
                        "an id is a letter or '_' followed by letters, digits, '_', '-' or '.', "
                        "found " +
                            Q(id)));
  } else if (id == "ground") {
    Add(e.file->AtValue(e.node, "id", 0, "the id 'ground' is reserved: it names the plane y = 0",
                        6));
  } else if (const auto it = ids.find(id); it != ids.end()) {
    const SourceLoc first =
        it->second.file->Locate(it->second.file->ElementOffset(it->second.node));
    Add(e.file->AtValue(e.node, "id", 0,
                        "duplicate id " + Q(id) + " (first on <" + std::string(it->second.name()) +
                            "> at " + first.file + ":" + std::to_string(first.line) + ":" +
                            std::to_string(first.column) + ")",
                        int(id.size())));
  } else {
    ids.emplace(id, e);
  }
}

template <typename Fn>
void Reader::Children(const Elem& parent, const std::vector<std::string_view>& allowed, Fn fn) {
  for (pugi::xml_node n : parent.node.children()) {
    if (n.type() == pugi::node_pcdata || n.type() == pugi::node_cdata) {
      const std::string_view v = n.value();
      if (v.find_first_not_of(" \t\r\n") != std::string_view::npos)
        Add(parent.file->AtElement(parent.node, "text inside <" + std::string(parent.name()) +
                                                    ">; values go in attributes"));
      continue;
    }
    if (n.type() != pugi::node_element) continue;
    Elem e{n, parent.file};
    std::string list;
    for (std::string_view k : allowed) list += (list.empty() ? "<" : ">, <") + std::string(k);
    list = allowed.empty() ? "nothing" : list + ">";
    if (e.name() == "ref" && !allowed.empty()) {
      Attrs a(*this, e);
      std::string target;
      if (!a.Has("id")) {
        Add(e.file->AtElement(n, "<ref> needs the 'id' of the element it repeats"));
        continue;
      }
      const std::string id = n.attribute("id").value();
      const auto it = ids.find(id);
      if (it == ids.end()) {
        std::vector<std::string_view> known;
        for (const auto& [k, t] : ids)
          if (std::find(allowed.begin(), allowed.end(), t.name()) != allowed.end())
            known.push_back(k);
        Add(e.file->AtValue(n, "id", 0, "no element has the id " + Q(id) + DidYouMean(id, known),
                            int(id.size())));
        continue;
      }
      if (std::find(allowed.begin(), allowed.end(), it->second.name()) == allowed.end()) {
        Add(e.file->AtValue(n, "id", 0,
                            Q(id) + " is a <" + std::string(it->second.name()) + ">, which <" +
                                std::string(parent.name()) + "> cannot hold; it takes " + list,
                            int(id.size())));
        continue;
      }
      NoChildren(e);
      fn(it->second);
      continue;
    }
    if (std::find(allowed.begin(), allowed.end(), e.name()) == allowed.end()) {
      std::vector<std::string_view> withRef = allowed;
      if (!allowed.empty()) withRef.push_back("ref");
      Add(e.file->AtElement(n, "<" + std::string(e.name()) + "> is not allowed inside <" +
                                   std::string(parent.name()) + ">" +
                                   DidYouMean(e.name(), withRef) + "; it takes " + list));
      continue;
    }
    fn(e);
  }
}

// ---------------------------------------------------------------------------
// Elements

const std::vector<std::pair<std::string_view, ForceKind>> kForceNames = {
    {"gravity", ForceKind::kGravity},
    {"drag", ForceKind::kDrag},
    {"attractor", ForceKind::kAttractor},
    {"vortex", ForceKind::kVortex},
    {"noise-force", ForceKind::kNoise}};

CameraDef Reader::ReadCamera(const Elem& e) {
  Attrs a(*this, e);
  CameraDef c;
  c.loc = a.Loc();
  Vec3 v;
  if (a.Vector("position", v)) c.position = v;
  a.Vector("target", c.target);
  if (a.Vector("orbit", v)) {
    if (v.z() <= 0)
      a.Error("orbit", "'orbit' is 'azimuth elevation distance' with a distance above 0");
    else
      c.orbit = v;
  }
  a.Vector("up", c.up, true);
  a.Number("fov", c.fovDegrees, Range{0, 180, true, true});
  double n = 0, f = 0;
  if (a.Number("near", n, kPositive)) c.near = n;
  if (a.Number("far", f, kPositive)) c.far = f;
  if (c.near && c.far && *c.far <= *c.near) a.Error("far", "'far' must be greater than 'near'");
  if (a.Has("position") && a.Has("orbit"))
    a.Error("orbit", "a camera has 'position' or 'orbit', not both");
  else if (!a.Has("position") && !a.Has("orbit"))
    Add(e.file->AtElement(e.node, "<camera> needs 'position' (with 'target') or 'orbit'"));
  if (c.position && (*c.position - c.target).norm() == 0)
    a.Error("target", "the camera's 'target' is its 'position'");
  NoChildren(e);
  return c;
}

LightDef Reader::ReadLight(const Elem& e) {
  Attrs a(*this, e);
  LightDef l;
  l.loc = a.Loc();
  a.Enum(
      "type", l.type,
      {{"sun", LightType::kSun}, {"ambient", LightType::kAmbient}, {"point", LightType::kPoint}});
  a.Vector("direction", l.direction, true);
  a.Vector("position", l.position);
  a.Color("color", l.color);
  a.Number("intensity", l.intensity, Between(0, 1e9));
  if (l.type == LightType::kPoint && a.Has("direction"))
    a.Error("direction", "a point light has a 'position', not a 'direction'");
  if (l.type == LightType::kPoint && !a.Has("position"))
    Add(e.file->AtElement(e.node, "a point light needs a 'position'"));
  if (l.type != LightType::kPoint && a.Has("position"))
    a.Error("position", "only a point light has a 'position'");
  if (l.type == LightType::kAmbient && a.Has("direction"))
    a.Error("direction", "an ambient light has no 'direction'");
  NoChildren(e);
  return l;
}

SkyDef Reader::ReadSky(const Elem& e) {
  Attrs a(*this, e);
  SkyDef s;
  s.loc = a.Loc();
  a.Color("top", s.top);
  a.Color("horizon", s.horizon);
  NoChildren(e);
  return s;
}

TerrainDef Reader::ReadTerrain(const Elem& e) {
  Attrs a(*this, e);
  TerrainDef t;
  t.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) t.id = id.value();
  const size_t errorsBefore = diags.ErrorCount();
  std::vector<double> size;
  if (a.Numbers("size", size, 2)) {
    if (size[0] >= 1e-3 && size[1] >= 1e-3 && size[0] <= 1e6 && size[1] <= 1e6)
      t.size = Vec2(size[0], size[1]);
    else
      a.Error("size", "'size' is 'x z' in metres, each from 0.001 to 1e6");
  }
  a.Count("resolution", t.resolution, 2, 8193);
  a.Number("height", t.height, Range{0, 1e5});
  a.Enum("noise", t.noise,
         {{"fbm", NoiseKind::kFbm},
          {"ridged", NoiseKind::kRidged},
          {"diamond-square", NoiseKind::kDiamondSquare},
          {"flat", NoiseKind::kFlat}});
  a.Count("octaves", t.octaves, 1, 16);
  a.Number("lacunarity", t.lacunarity, Range{1, 8});
  a.Number("gain", t.gain, Range{0, 1, true, false});
  uint64_t seed = 0;
  if (a.Count("seed", seed, 0, uint64_t(1) << 53)) t.seed = seed;
  a.Color("color", t.color);
  if (t.noise == NoiseKind::kDiamondSquare && ((t.resolution - 1) & (t.resolution - 2)) != 0)
    a.Error("resolution",
            "diamond-square needs a resolution of 2^k + 1 (129, 257, 513 ...), found " +
                std::to_string(t.resolution));
  // What the terrain library checks beyond each attribute's range (the
  // finest octave's lattice within float precision), here rather than
  // when the scene is built.
  if (diags.ErrorCount() == errorsBefore) {
    if (Status st = terrain::Validate(TerrainDefOf(t, 0)); !st.ok()) {
      std::string message = st.error().message;
      if (message.rfind("TerrainDef: ", 0) == 0) message = "<terrain>: " + message.substr(12);
      Add(e.file->AtElement(e.node, message + "; lower 'octaves' or 'lacunarity'"));
    }
  }
  AddSize(e, "resolution", uint64_t(t.resolution) * uint64_t(t.resolution) * 128,
          "<terrain resolution>");
  NoChildren(e);
  return t;
}

std::vector<Define> Reader::ReadDefines(const Elem& e) {
  std::vector<Define> out;
  Children(e, {"define"}, [&](const Elem& d) {
    Attrs a(*this, d);
    Define def;
    def.loc = a.Loc();
    const std::optional<std::string> name = a.Text("name");
    if (!name || name->empty()) {
      Add(d.file->AtElement(d.node, "<define> needs 'name' and 'value'"));
      return;
    }
    if (!a.Has("value")) {
      Add(d.file->AtElement(d.node, "<define> needs 'name' and 'value'"));
      return;
    }
    def.name = *name;
    if (a.Number("value", def.value)) out.push_back(def);
    NoChildren(d);
  });
  return out;
}

PlantDef Reader::ReadPlant(const Elem& e) {
  Attrs a(*this, e);
  PlantDef p;
  p.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) p.id = id.value();
  if (!a.Has("grammar")) Add(e.file->AtElement(e.node, "<plant> needs a 'grammar' file"));
  a.Path("grammar", p.grammar, &p.grammarLoc);
  int steps = 0;
  if (a.Count("steps", steps, 0, 1000)) p.steps = steps;
  uint64_t seed = 0;
  if (a.Count("seed", seed, 0, uint64_t(1) << 53)) p.seed = seed;
  // position: "x z" puts the plant on the terrain; "x y z" places it.
  if (const std::optional<std::string> t = a.Text("position")) {
    const Parsed<std::vector<double>> two = ParseNumbers(*t, 2);
    if (two.ok()) {
      p.position = Vec3((*two.value)[0], 0, (*two.value)[1]);
    } else if (a.Vector("position", p.position)) {
      p.positionHasY = true;
    }
  }
  a.Number("rotate", p.rotateDegrees);
  a.Number("scale", p.scale, kPositive);
  double height = 0;
  if (a.Number("height", height, kPositive)) p.height = height;
  p.defines = ReadDefines(e);
  return p;
}

ForestDef Reader::ReadForest(const Elem& e) {
  Attrs a(*this, e);
  ForestDef f;
  f.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) f.id = id.value();
  if (!a.Has("grammar")) Add(e.file->AtElement(e.node, "<forest> needs a 'grammar' file"));
  a.Path("grammar", f.grammar, &f.grammarLoc);
  if (!a.Has("count")) Add(e.file->AtElement(e.node, "<forest> needs a 'count'"));
  a.Count("count", f.count, 0, 10000000);
  a.Ref("on", f.on, {"terrain"}, true);
  std::vector<double> area;
  if (a.Numbers("area", area, 4)) {
    bool inRange = true;
    for (double x : area) inRange = inRange && std::abs(x) <= 1e7;
    if (!inRange)
      a.Error("area", "'area' coordinates are metres within -1e7..1e7");
    else if (area[2] > area[0] && area[3] > area[1])
      f.area = Vec4(area[0], area[1], area[2], area[3]);
    else
      a.Error("area", "'area' is 'x0 z0 x1 z1' with x1 > x0 and z1 > z0");
  }
  a.Number("min-distance", f.minDistance, kNonNegative);
  a.Count("variants", f.variants, 1, 1024);
  std::vector<double> scale;
  if (a.Numbers("scale", scale, 2)) {
    if (scale[0] > 0 && scale[1] >= scale[0])
      f.scale = Vec2(scale[0], scale[1]);
    else
      a.Error("scale", "'scale' is 'min max' with 0 < min <= max");
  }
  double height = 0;
  if (a.Number("height", height, kPositive)) f.height = height;
  int steps = 0;
  if (a.Count("steps", steps, 0, 1000)) f.steps = steps;
  uint64_t seed = 0;
  if (a.Count("seed", seed, 0, uint64_t(1) << 53)) f.seed = seed;
  f.defines = ReadDefines(e);
  // An instance is a transform and a variant index; the variants' meshes
  // are counted when they are built.
  AddSize(e, "count", uint64_t(f.count) * 512, "<forest count>");
  return f;
}

EmitterDef Reader::ReadEmitter(const Elem& e) {
  Attrs a(*this, e);
  EmitterDef m;
  m.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) m.id = id.value();
  a.Enum("shape", m.shape,
         {{"point", EmitterShape::kPoint},
          {"sphere", EmitterShape::kSphere},
          {"box", EmitterShape::kBox},
          {"disc", EmitterShape::kDisc},
          {"terrain", EmitterShape::kTerrain},
          {"plant", EmitterShape::kPlant}});
  a.Vector("at", m.at);
  // size: one number (every axis) or "x y z".
  if (const std::optional<std::string> t = a.Text("size")) {
    const Parsed<double> one = ParseNumber(*t);
    if (one.ok())
      m.size = Vec3::Constant(*one.value);
    else
      a.Vector("size", m.size);
    if ((m.size.array() < 0).any()) a.Error("size", "'size' must be 0 or more on every axis");
  }
  const bool onSomething = m.shape == EmitterShape::kTerrain || m.shape == EmitterShape::kPlant;
  if (onSomething) {
    if (!a.Has("of"))
      Add(e.file->AtElement(e.node, "an emitter of shape terrain or plant needs 'of'"));
    if (m.shape == EmitterShape::kTerrain)
      a.Ref("of", m.of, {"terrain"});
    else
      a.Ref("of", m.of, {"plant", "forest"});
  } else if (a.Has("of")) {
    a.Error("of", "'of' is for emitters of shape terrain or plant");
  }
  a.Enum("part", m.part,
         {{"leaves", PlantPart::kLeaves},
          {"tips", PlantPart::kTips},
          {"segments", PlantPart::kSegments}});
  if (a.Has("part") && m.shape != EmitterShape::kPlant)
    a.Error("part", "'part' is for emitters of shape plant");
  a.Number("rate", m.rate, Range{0, 1e9});
  a.Count("burst", m.burst, 0, kMaxCount);
  a.Vector("direction", m.direction, true);
  a.Number("speed", m.speed, kNonNegative);
  a.Number("spread", m.spreadDegrees, Range{0, 180});
  if (const std::optional<std::string> t = a.Text("lifetime")) {
    const Parsed<double> one = ParseNumber(*t);
    std::vector<double> two;
    if (one.ok())
      m.lifetime = Vec2(*one.value, *one.value);
    else if (a.Numbers("lifetime", two, 2))
      m.lifetime = Vec2(two[0], two[1]);
    if (!(m.lifetime.x() > 0 && m.lifetime.y() >= m.lifetime.x()))
      a.Error("lifetime", "'lifetime' is seconds, 'min max' with 0 < min <= max");
  }
  a.Number("mass", m.mass, kPositive);
  a.Number("radius", m.radius, kNonNegative);
  NoChildren(e);
  return m;
}

ForceDef Reader::ReadForce(const Elem& e) {
  Attrs a(*this, e);
  ForceDef f;
  f.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) f.id = id.value();
  for (const auto& [n, k] : kForceNames)
    if (e.name() == n) f.kind = k;
  switch (f.kind) {
    case ForceKind::kGravity:
      a.Vector("g", f.g);
      break;
    case ForceKind::kDrag:
      if (!a.Has("k")) Add(e.file->AtElement(e.node, "<drag> needs 'k'"));
      a.Number("k", f.k, kNonNegative);
      a.Bool("quadratic", f.quadratic);
      break;
    case ForceKind::kAttractor: {
      Vec3 p;
      if (a.Vector("position", p)) f.position = p;
      a.Ref("of", f.of, {"plant", "cloth", "emitter", "flock"});
      if (a.Has("position") == a.Has("of"))
        Add(e.file->AtElement(e.node, "<attractor> needs 'position' or 'of' (one of them)"));
      a.Number("strength", f.strength);
      a.Enum("falloff", f.falloff,
             {{"inverse-square", Falloff::kInverseSquare}, {"linear", Falloff::kLinear}});
      a.Number("radius", f.radius, kNonNegative);
      break;
    }
    case ForceKind::kVortex:
    case ForceKind::kNoise: {
      Vec3 p;
      if (a.Vector("position", p)) f.position = p;
      a.Vector("axis", f.axis, true);
      a.Number("strength", f.strength);
      a.Number("scale", f.scale, kPositive);
      a.Number("frequency", f.frequency, kNonNegative);
      break;
    }
  }
  NoChildren(e);
  return f;
}

CollideDef Reader::ReadCollide(const Elem& e) {
  Attrs a(*this, e);
  CollideDef c;
  c.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) c.id = id.value();
  if (!a.Has("with"))
    Add(e.file->AtElement(e.node,
                          "<collide> needs 'with' (ids of terrain, plants, forests, "
                          "cloth, or 'ground')"));
  a.Refs("with", c.with, {"terrain", "plant", "forest", "cloth"}, true, &c.withLoc);
  a.Number("restitution", c.restitution, Between(0, 1));
  a.Number("friction", c.friction, kNonNegative);
  a.Bool("stick", c.stick);
  NoChildren(e);
  return c;
}

SpringsDef Reader::ReadSprings(const Elem& e) {
  Attrs a(*this, e);
  SpringsDef s;
  s.loc = a.Loc();
  a.Enum("between", s.between,
         {{"chain", SpringTopology::kChain},
          {"grid", SpringTopology::kGrid},
          {"nearest", SpringTopology::kNearest}});
  a.Number("k", s.k, kNonNegative);
  a.Number("damping", s.damping, kNonNegative);
  double rest = 0;
  if (a.Number("rest", rest, kNonNegative)) s.rest = rest;
  NoChildren(e);
  return s;
}

OnDeathDef Reader::ReadOnDeath(const Elem& e) {
  Attrs a(*this, e);
  OnDeathDef o;
  o.loc = a.Loc();
  if (!a.Has("emit") || !a.Has("count"))
    Add(e.file->AtElement(e.node, "<on-death> needs 'emit' (a particles id) and 'count'"));
  a.Ref("emit", o.emit, {"particles"});
  a.Count("count", o.count, 0, 1000000);
  NoChildren(e);
  return o;
}

DrawDef Reader::ReadDraw(const Elem& e) {
  Attrs a(*this, e);
  DrawDef d;
  d.loc = a.Loc();
  a.Enum("as", d.as,
         {{"points", DrawAs::kPoints},
          {"sprites", DrawAs::kSprites},
          {"mesh", DrawAs::kMesh},
          {"trails", DrawAs::kTrails}});
  if (const std::optional<std::string> t = a.Text("mesh")) {
    if (t->empty()) a.Error("mesh", "'mesh' is a surface '~name' or an .obj file");
    if (!t->empty() && (*t)[0] == '~')
      d.mesh = *t;
    else
      a.Path("mesh", d.mesh);
  }
  if (d.as == DrawAs::kMesh && d.mesh.empty())
    Add(e.file->AtElement(e.node,
                          "<draw as=\"mesh\"> needs 'mesh' (a surface '~leaf' or an .obj)"));
  if (d.as != DrawAs::kMesh && a.Has("mesh")) a.Error("mesh", "'mesh' is for as=\"mesh\"");
  a.Number("size", d.size, Range{0, 1e6, true, false});
  // color: one colour, or two (start and end of life).
  if (std::optional<std::string> t = a.Text("color")) {
    const size_t first = t->find_first_not_of(" \t\r\n");
    const size_t last = t->find_last_not_of(" \t\r\n");
    *t = first == std::string::npos ? std::string() : t->substr(first, last - first + 1);
    const Parsed<Vec3> one = ParseColor(*t);
    const Parsed<std::vector<double>> six = ParseNumbers(*t, 6);
    const size_t space = t->find_first_of(" \t");
    if (one.ok()) {
      d.color = *one.value;
    } else if (six.ok()) {
      const std::vector<double>& v = *six.value;
      bool inRange = true;
      for (double x : v) inRange = inRange && x >= 0 && x <= 1;
      if (!inRange) a.Error("color", "linear colours are 0..1 in each component");
      d.color = Vec3(v[0], v[1], v[2]);
      d.colorEnd = Vec3(v[3], v[4], v[5]);
    } else if (space != std::string::npos && (*t)[0] == '#') {
      const size_t second = t->find_first_not_of(" \t", space);
      const Parsed<Vec3> c0 = ParseColor(t->substr(0, space));
      const Parsed<Vec3> c1 = ParseColor(second == std::string::npos ? "" : t->substr(second));
      if (c0.ok() && c1.ok()) {
        d.color = *c0.value;
        d.colorEnd = *c1.value;
      } else {
        a.ValueError("color", c0.ok() ? c1.error : c0.error);
      }
    } else {
      a.ValueError("color", one.error);
    }
  }
  a.Number("alpha", d.alpha, Between(0, 1));
  a.Enum("blend", d.blend, {{"alpha", Blend::kAlpha}, {"additive", Blend::kAdditive}});
  a.Number("spin", d.spinDegrees, Between(-1e6, 1e6));
  NoChildren(e);
  return d;
}

ParticlesDef Reader::ReadParticles(const Elem& e) {
  Attrs a(*this, e);
  ParticlesDef p;
  p.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) p.id = id.value();
  a.Count("max", p.max, 1, kMaxCount);
  a.Enum("integrator", p.integrator,
         {{"symplectic", Integrator::kSymplectic},
          {"euler", Integrator::kEuler},
          {"rk2", Integrator::kRk2},
          {"rk4", Integrator::kRk4},
          {"rk45", Integrator::kRk45},
          {"implicit", Integrator::kImplicit}});
  a.Count("substeps", p.substeps, 1, 1000);
  a.Bool("wind", p.wind);
  bool drawSeen = false;
  Children(e,
           {"emitter", "gravity", "drag", "attractor", "vortex", "noise-force", "collide",
            "springs", "self-collide", "on-death", "draw"},
           [&](const Elem& c) {
             if (c.name() == "emitter") p.emitters.push_back(ReadEmitter(c));
             if (c.name() == "collide") p.collides.push_back(ReadCollide(c));
             if (c.name() == "springs") p.springs.push_back(ReadSprings(c));
             if (c.name() == "on-death") p.onDeath.push_back(ReadOnDeath(c));
             for (const auto& [n, k] : kForceNames)
               if (c.name() == n) p.forces.push_back(ReadForce(c));
             if (c.name() == "self-collide") {
               if (p.selfCollideRestitution)
                 Add(c.file->AtElement(c.node, "a second <self-collide> in one system"));
               Attrs sa(*this, c);
               double r = 0.5;
               sa.Number("restitution", r, Between(0, 1));
               p.selfCollideRestitution = r;
               NoChildren(c);
             }
             if (c.name() == "draw") {
               if (drawSeen)
                 Add(c.file->AtElement(c.node, "a second <draw>; a system draws one way"));
               drawSeen = true;
               p.draw = ReadDraw(c);
             }
           });
  if (p.emitters.empty()) {
    Diagnostic d = e.file->AtElement(e.node,
                                     "<particles> has no <emitter>: no particle is ever born "
                                     "unless another system's <on-death> emits into it");
    d.severity = Severity::kWarning;
    if (p.id.empty()) Add(std::move(d));
  }
  // A System particle: position, velocity, force, previous position (double,
  // 96 bytes), mass, birth, lifetime, radius, id (about 40 more).
  AddSize(e, "max", p.max * 160, "<particles max>");
  return p;
}

ClothDef Reader::ReadCloth(const Elem& e) {
  Attrs a(*this, e);
  ClothDef c;
  c.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) c.id = id.value();
  std::vector<double> v;
  if (a.Numbers("size", v, 2)) {
    if (v[0] > 0 && v[1] > 0)
      c.size = Vec2(v[0], v[1]);
    else
      a.Error("size", "'size' is 'width height' in metres, both above 0");
  }
  if (a.Numbers("resolution", v, 2)) {
    // ClothDef's range for each: a product bound alone let 2^31 columns by
    // 2 rows through to the conversion to int (undefined behaviour).
    if (v[0] >= 2 && v[1] >= 2 && v[0] <= 10000 && v[1] <= 10000 && v[0] == std::floor(v[0]) &&
        v[1] == std::floor(v[1])) {
      c.columns = int(v[0]);
      c.rows = int(v[1]);
    } else {
      a.Error("resolution", "'resolution' is 'columns rows', whole numbers from 2 to 10000");
    }
  }
  a.Vector("position", c.position);
  a.Vector("rotate", c.rotateDegrees);
  a.Enum(
      "pin", c.pin,
      {{"top", Pin::kTop}, {"left", Pin::kLeft}, {"corners", Pin::kCorners}, {"none", Pin::kNone}});
  if (const std::optional<std::string> t = a.Text("pin-ids")) {
    if (a.Has("pin")) a.Error("pin-ids", "a cloth has 'pin' or 'pin-ids', not both");
    const Parsed<std::vector<std::string>> pins = ParseNames(*t);
    const uint64_t n = uint64_t(c.columns) * uint64_t(c.rows);
    if (!pins.ok()) a.ValueError("pin-ids", pins.error);
    for (const std::string& s : pins.ok() ? *pins.value : std::vector<std::string>{}) {
      const Parsed<uint64_t> id = ParseCount(s, n - 1);
      if (!id.ok()) {
        a.ValueError("pin-ids",
                     {"vertex id " + Q(s) + ": " + id.error.message, t->find(s), int(s.size())});
        break;
      }
      c.pinIds.push_back(int(*id.value));
    }
    c.pin = Pin::kIds;
  }
  a.Enum("solver", c.solver, {{"xpbd", ClothSolver::kXpbd}, {"implicit", ClothSolver::kImplicit}});
  a.Number("stretch", c.stretch, kNonNegative);
  a.Number("bend", c.bend, kNonNegative);
  a.Number("damping", c.damping, kNonNegative);
  a.Color("color", c.color);
  a.Bool("wind", c.wind);
  Children(e, {"gravity", "drag", "attractor", "vortex", "noise-force", "collide"},
           [&](const Elem& ch) {
             if (ch.name() == "collide")
               c.collides.push_back(ReadCollide(ch));
             else
               c.forces.push_back(ReadForce(ch));
           });
  // Vertex state and about six constraints a vertex.
  AddSize(e, "resolution", uint64_t(c.columns) * uint64_t(c.rows) * 800, "<cloth resolution>");
  return c;
}

FlockDef Reader::ReadFlock(const Elem& e) {
  Attrs a(*this, e);
  FlockDef f;
  f.loc = a.Loc();
  if (const pugi::xml_attribute id = e.node.attribute("id")) f.id = id.value();
  a.Count("count", f.count, 1, 100000000);
  std::vector<double> b;
  if (a.Numbers("bounds", b, 6)) {
    if (b[3] > b[0] && b[4] > b[1] && b[5] > b[2]) {
      f.boundsMin = Vec3(b[0], b[1], b[2]);
      f.boundsMax = Vec3(b[3], b[4], b[5]);
    } else {
      a.Error("bounds", "'bounds' is 'x0 y0 z0 x1 y1 z1' with each max above its min");
    }
  }
  a.Number("speed", f.speed, kPositive);
  a.Number("cohesion", f.cohesion, kNonNegative);
  a.Number("separation", f.separation, kNonNegative);
  a.Number("alignment", f.alignment, kNonNegative);
  a.Refs("avoid", f.avoid, {"plant", "forest", "terrain", "cloth"}, true, &f.avoidLoc);
  a.Bool("wind", f.wind);
  bool drawSeen = false;
  Children(e, {"gravity", "drag", "attractor", "vortex", "noise-force", "draw"},
           [&](const Elem& c) {
             if (c.name() == "draw") {
               if (drawSeen)
                 Add(c.file->AtElement(c.node, "a second <draw>; a flock draws one way"));
               drawSeen = true;
               f.draw = ReadDraw(c);
             } else {
               f.forces.push_back(ReadForce(c));
             }
           });
  AddSize(e, "count", uint64_t(f.count) * 256, "<flock count>");
  return f;
}

WindDef Reader::ReadWind(const Elem& e) {
  Attrs a(*this, e);
  WindDef w;
  w.loc = a.Loc();
  a.Vector("velocity", w.velocity);
  a.Number("gust", w.gust, kNonNegative);
  a.Number("scale", w.scale, kPositive);
  a.Number("frequency", w.frequency, kNonNegative);
  NoChildren(e);
  return w;
}

SimulationDef Reader::ReadSimulation(const Elem& e) {
  Attrs a(*this, e);
  SimulationDef s;
  s.loc = a.Loc();
  a.Number("fps", s.fps, Range{0, 1000, true, false});
  a.Count("substeps", s.substeps, 1, 1000);
  a.Number("duration", s.duration, Range{0, 1e6});
  a.Count("threads", s.threads, 0, 256);
  NoChildren(e);
  return s;
}

void Reader::ReadTop(const Elem& e) {
  const std::string name(e.name());
  static const std::vector<std::string_view> kSingletons = {"camera", "sky", "wind", "simulation"};
  if (std::find(kSingletons.begin(), kSingletons.end(), name) != kSingletons.end()) {
    const SourceLoc here = e.file->Locate(e.file->ElementOffset(e.node));
    const auto [it, fresh] = singletons_.emplace(name, here);
    if (!fresh) {
      Add(e.file->AtElement(e.node, "a second <" + name + ">; a scene has one (the first is at " +
                                        it->second.file + ":" + std::to_string(it->second.line) +
                                        ")"));
      return;
    }
  }
  if (name == "default") return;  // read with the parameters
  if (name == "camera")
    scene_.camera = ReadCamera(e);
  else if (name == "light") {
    if (scene_.lights.size() == kMaxLights)
      Add(e.file->AtElement(e.node, "more than " + std::to_string(kMaxLights) +
                                        " lights; the renderer takes at most " +
                                        std::to_string(kMaxLights)));
    scene_.lights.push_back(ReadLight(e));
  } else if (name == "sky")
    scene_.sky = ReadSky(e);
  else if (name == "terrain")
    scene_.terrains.push_back(ReadTerrain(e));
  else if (name == "plant")
    scene_.plants.push_back(ReadPlant(e));
  else if (name == "forest")
    scene_.forests.push_back(ReadForest(e));
  else if (name == "particles")
    scene_.particles.push_back(ReadParticles(e));
  else if (name == "cloth")
    scene_.cloths.push_back(ReadCloth(e));
  else if (name == "flock")
    scene_.flocks.push_back(ReadFlock(e));
  else if (name == "wind")
    scene_.wind = ReadWind(e);
  else if (name == "simulation")
    scene_.simulation = ReadSimulation(e);
  else {
    static const std::vector<std::string_view> kTop = {
        "default", "include",   "camera", "light", "sky",  "terrain",   "plant",
        "forest",  "particles", "cloth",  "flock", "wind", "simulation"};
    Add(e.file->AtElement(e.node, "unknown element <" + name + ">" + DidYouMean(name, kTop) +
                                      "; <scene> takes <default>, <include>, <camera>, <light>, "
                                      "<sky>, <terrain>, <plant>, <forest>, <particles>, "
                                      "<cloth>, <flock>, <wind>, <simulation>"));
  }
}

void Reader::CheckMemory() {
  uint64_t budget = options_.memoryBudget;
  if (budget == 0) {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    budget = pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : uint64_t(1) << 34;
  }
  uint64_t total = 0;
  const Size* biggest = nullptr;
  for (const Size& s : sizes_) {
    total += s.bytes;  // each term is below 2^40 * 400
    if (!biggest || s.bytes > biggest->bytes) biggest = &s;
  }
  if (total <= budget || !biggest) return;
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "the declared sizes need about %.1f GiB, more than the %.1f GiB this machine has "
                "(the largest is this %s: %.1f GiB)",
                double(total) / double(1 << 30), double(budget) / double(1 << 30),
                biggest->what.c_str(), double(biggest->bytes) / double(1 << 30));
  Diagnostic d = biggest->at;
  d.message = buf;
  Add(std::move(d));
}

ReadResult Reader::Run(const std::string& path) {
  std::vector<std::string> chain;
  const bool loaded = Load(path, 0, chain, nullptr, top_);
  ReadResult result;
  if (loaded) {
    scene_.path = path;
    ReadRootAttributes(root_);
    CollectDefaults();
    for (const Elem& e : top_) CollectIds(e);
    if (!badNesting_)
      for (const Elem& e : top_) ReadTop(e);
    if (!diags.HasErrors()) CheckMemory();
  }
  if (!diags.HasErrors()) result.scene = std::move(scene_);
  // In reading order: command-line errors, then file by file, line by line
  // (the passes find them in another order).
  auto rank = [&](const Diagnostic& d) {
    size_t file = 0;
    while (file < files_.size() && files_[file]->path() != d.loc.file) ++file;
    return std::make_tuple(d.loc.file.empty() ? 0 : 1, file, d.loc.line, d.loc.column);
  };
  std::stable_sort(diags.items.begin(), diags.items.end(),
                   [&](const Diagnostic& a, const Diagnostic& b) { return rank(a) < rank(b); });
  result.diagnostics = std::move(diags);
  return result;
}

}  // namespace

ReadResult ReadScene(const std::string& path, const ReadOptions& options) {
  Reader r(options);
  return r.Run(path);
}

}  // namespace sylva::scene
