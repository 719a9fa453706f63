#include "plant/surface_library.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include <set>

#include "mesh/obj_reader.h"

namespace sylva::plant {

std::string BundledDataDir() {
  // $SYLVA_DATA_DIR; else share/sylva beside an installed executable, or
  // where `cmake --install` put it; else the source tree of this build.
  if (const char* env = std::getenv("SYLVA_DATA_DIR"); env && *env) return env;
  auto isDir = [](const std::string& p) {
    struct stat st;
    return ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
  };
  char exe[4096];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    std::string dir(exe, size_t(n));
    for (int up = 0; up < 3 && dir.rfind('/') != std::string::npos; ++up) {
      dir = dir.substr(0, dir.rfind('/'));
      if (isDir(dir + "/share/sylva/grammars")) return dir + "/share/sylva";
    }
  }
  if (isDir(std::string(SYLVA_INSTALLED_DATA_DIR) + "/grammars")) return SYLVA_INSTALLED_DATA_DIR;
  return SYLVA_DATA_DIR;
}

static std::string Join(const std::string& dir, const std::string& name) {
  if (dir.empty()) return name;
  return dir.back() == '/' ? dir + name : dir + "/" + name;
}

static std::string ParentOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

SurfaceLibrary::SurfaceLibrary(const std::string& grammarPath,
                               const std::vector<std::string>& extra, FileReader readFile)
    : searchPath_(extra), readFile_(std::move(readFile)) {
  const std::string dir = ParentOf(grammarPath);
  searchPath_.push_back(dir);
  searchPath_.push_back(Join(dir, "surfaces"));
  searchPath_.push_back(Join(Join(BundledDataDir(), "grammars"), "surfaces"));
}

std::string SurfaceLibrary::Locate(const std::string& name,
                                   std::optional<std::string>* text) const {
  const std::string file = name + ".obj";
  for (const std::string& dir : searchPath_) {
    const std::string candidate = Join(dir, file);
    if (readFile_) {
      *text = readFile_(candidate);
      if (*text) return candidate;
      continue;
    }
    struct stat st;
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode)) return candidate;
  }
  return {};
}

void SurfaceLibrary::Define(const std::vector<CpfgSurfaceDef>& defs) {
  for (const CpfgSurfaceDef& d : defs) cpfg_[d.name] = d;
}

Status SurfaceLibrary::LoadCpfg(const CpfgSurfaceDef& def) {
  if (def.missing) {  // warned where the view file names it
    meshes_.emplace(def.name, mesh::TriangleMesh());
    return {};
  }
  std::optional<std::string> text;
  if (readFile_) {
    text = readFile_(def.file);
  } else {
    struct stat st;
    if (::stat(def.file.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_size < (64 << 20)) {
      if (FILE* f = std::fopen(def.file.c_str(), "rb")) {
        std::string bytes(size_t(st.st_size), '\0');
        const size_t got = std::fread(bytes.data(), 1, bytes.size(), f);
        std::fclose(f);
        if (got == bytes.size()) text = std::move(bytes);
      }
    }
  }
  if (!text) {
    return MakeError(SourceLoc{def.viewFile, def.line, 0},
                     "cannot read the surface file " + def.file + " of surface '" + def.name + "'");
  }
  auto m = ParseCpfgSurface(*text, def.file, def.size, def.sPrecision, def.tPrecision);
  if (!m) return m.error();
  meshes_.emplace(def.name, std::move(*m));
  return {};
}

bool SurfaceLibrary::Has(const std::string& name) const {
  if (meshes_.count(name) || cpfg_.count(name)) return true;
  std::optional<std::string> text;
  return !Locate(name, &text).empty();
}

Status SurfaceLibrary::LoadFor(const mesh::PlantGeometry& geometry, const lsys::Grammar& g,
                               DiagnosticList* warnings) {
  std::set<std::string> names;
  for (const auto& si : geometry.surfaces) {
    if (!meshes_.count(si.name)) names.insert(si.name);
  }
  for (const std::string& name : names) {
    if (auto it = cpfg_.find(name); it != cpfg_.end()) {
      if (Status s = LoadCpfg(it->second); !s.ok()) return s;
      continue;
    }
    const std::string file = name + ".obj";
    std::optional<std::string> text;
    const std::string found = Locate(name, &text);
    if (found.empty()) {
      Diagnostic d;
      d.severity = Severity::kWarning;
      d.loc.file = g.path;
      d.message = "unknown surface '" + name +
                  "' is not drawn (as in cpfg): no view-file 'surface: " + name +
                  "' line, and no " + file + " in";
      for (size_t i = 0; i < searchPath_.size(); ++i) {
        d.message += (i ? ", " : " ") + searchPath_[i];
      }
      if (name.size() > 1) {
        d.message += " (cpfg surface names are one letter: with " + name.substr(0, 1) +
                     ".obj there, '~" + name + "' is read as '~" + name.substr(0, 1) +
                     "' followed by '" + name.substr(1) + "')";
      }
      // Point at the surface's first use in the grammar.
      if (auto it = g.symbolLoc.find("~" + name); it != g.symbolLoc.end()) {
        d.loc = it->second.loc;
        SetExcerpt(d, g.SourceLine(d.loc));
        d.length = int(name.size()) + 1;
      }
      if (warnings) warnings->Add(std::move(d));
      meshes_.emplace(name, mesh::TriangleMesh());
      continue;
    }
    auto surface = text ? mesh::ParseObj(*text, found) : mesh::ReadObj(found);
    if (!surface) return surface.error();
    meshes_.emplace(name, std::move(*surface));
  }
  return {};
}

}  // namespace sylva::plant
