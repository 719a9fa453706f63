// Reads a scene file (SCENE.md; every element and attribute in
// docs/scene.md) into the scene model (scene.h), strictly:
//  - an unknown element or attribute, a missing required attribute, a value
//    of the wrong type or out of range, a duplicate or dangling id: each is
//    an error at file:line:col (the attribute itself, or the byte of its
//    value), with "did you mean 'x'?" when a known name is within two
//    edits;
//  - `<default name value/>` declares a parameter that any attribute may use
//    as `$name`; ReadOptions::defines (the command line's -D) overrides it,
//    and naming an undeclared parameter there is an error;
//  - `<include file/>` splices another scene file (relative to the including
//    file), at most 15 levels below the root, a cycle is an error naming the
//    chain;
//  - declared sizes (particles' max, terrain resolution, cloth resolution,
//    flock and forest counts) are checked against memory before anything is
//    built.
// The scene loads whole or not at all: `scene` is set only when there is no
// error (warnings may come with it).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "core/status.h"
#include "scene/scene.h"

namespace sylva::scene {

struct ReadOptions {
  std::vector<std::string> defines;  // "NAME=VALUE", as -D gives them
  // Reads one file; empty: core's ReadFile (regular files only, 64 MiB).
  std::function<Expected<std::string>(const std::string& path)> readFile;
  // Estimated bytes the declared sizes may need; 0: physical memory.
  uint64_t memoryBudget = 0;
};

// Every file a scene may include, in all: files and bytes.
inline constexpr size_t kMaxSceneFiles = 1000;
inline constexpr size_t kMaxSceneBytes = size_t(256) << 20;
// The root is depth 0; an include at depth 15 may not include again.
inline constexpr int kMaxIncludeDepth = 15;

struct ReadResult {
  std::optional<Scene> scene;
  DiagnosticList diagnostics;
};

ReadResult ReadScene(const std::string& path, const ReadOptions& options = {});

// The scene file's folder: grammar and include paths are relative to it.
std::string FolderOf(const std::string& path);

}  // namespace sylva::scene
