#pragma once
// Entries by name, in registration order: what the layout and technique
// registries (layout/LayoutRegistry.h, render/TechniqueRegistry.h) share.
// Entry is any type with a `std::string name`.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {

template <class Entry>
class NamedRegistry {
 public:
  // `kind` names an entry in messages ("layout"); `firstChoice` is a choice
  // a user has besides the entries ("auto"), listed first.
  explicit NamedRegistry(std::string kind, std::string firstChoice = "")
      : kind_(std::move(kind)), firstChoice_(std::move(firstChoice)) {}

  // Adds an entry after the others, or replaces the one of the same name.
  void add(Entry entry) {
    for (Entry& e : entries_) {
      if (e.name == entry.name) {
        e = std::move(entry);
        return;
      }
    }
    entries_.push_back(std::move(entry));
  }

  const std::vector<Entry>& entries() const { return entries_; }

  std::vector<std::string> names() const {
    std::vector<std::string> names;
    for (const Entry& e : entries_) names.push_back(e.name);
    return names;
  }

  bool contains(const std::string& name) const {
    return std::any_of(entries_.begin(), entries_.end(),
                       [&](const Entry& e) { return e.name == name; });
  }

  // What a user may ask for: "auto, texture3d, mosaic or packed-mosaic".
  std::string choices() const {
    std::string text = firstChoice_;
    for (std::size_t i = 0; i < entries_.size(); ++i) {
      if (!text.empty()) text += i + 1 == entries_.size() ? " or " : ", ";
      text += entries_[i].name;
    }
    return text;
  }

  // InputError "unknown layout 'x' (expected auto, texture3d, ...)" when
  // there is no entry of that name.
  const Entry& find(const std::string& name) const {
    for (const Entry& e : entries_) {
      if (e.name == name) return e;
    }
    throw InputError("unknown " + kind_ + " '" + name + "' (expected " + choices() + ")");
  }

 private:
  std::string kind_;
  std::string firstChoice_;
  std::vector<Entry> entries_;
};

}  // namespace tessera
