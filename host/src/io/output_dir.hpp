#pragma once
// A directory written as one set of files: built beside its target and swapped in with one
// rename, so a reader finds one writer's files or none, never a mix of two (docs/design.md,
// "CLI contract").

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace::io {

/// Which names an existing target may hold for replace_directory to replace it.
using NamePredicate = std::function<bool(const std::string& name)>;

/// Throws InputError unless replace_directory could replace `target`: it is a directory or
/// absent, every entry's name passes `ours`, and the folder it goes in (or that folder's
/// first existing ancestor) is writable.
void check_replaceable(const std::filesystem::path& target, const NamePredicate& ours);

/// Replaces the directory `target` (created if missing, symlinks in its path resolved) by one
/// holding exactly `files` (name, bytes). The set is written into `.NAME.groovetrace-XXXXXX`
/// beside the target, each file flushed, then exchanged with the target in one
/// renameat2(RENAME_EXCHANGE); on a file system without it, two renames (the target is then
/// absent for an instant, never mixed). Writers into one folder serialize their swaps with an
/// flock(2) on the folder, so of two concurrent writers the later one wins whole. Temporaries
/// that killed writers left beside the target (nobody holds their flock) are removed first.
/// Throws InputError, with the target unchanged, when check_replaceable fails or a file
/// cannot be written.
void replace_directory(const std::filesystem::path& target,
                       const std::vector<std::pair<std::string, std::string>>& files,
                       const NamePredicate& ours);

}  // namespace groovetrace::io
