#!/usr/bin/env bash
# scripts/fetch_data against a tiny local bare repository made here (no network): the checkout
# is at the config's commit with only the source's paths, a second run fetches nothing, a new
# commit moves the folder, and bad commits, conflicting commits and a folder that is not a
# checkout are refused with messages naming them. Exit 77 (skipped) without git or PyYAML.
# Usage: fetch_data_test.sh <source dir>
set -euo pipefail

source_dir=$1
fetch="$source_dir/scripts/fetch_data"
command -v git > /dev/null || { echo "skipped: git is not installed"; exit 77; }
python3 -c 'import yaml' 2> /dev/null || { echo "skipped: python3-yaml is not installed"; exit 77; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAILED: $*" >&2; exit 1; }
expect_in() {  # expect_in <text> <needle>...
  local text=$1; shift
  for needle in "$@"; do
    [[ "$text" == *"$needle"* ]] || fail "missing '$needle' in: $text"
  done
}

git_() { git -c user.name=test -c user.email=test@example.org -c init.defaultBranch=main "$@"; }
git_ init -q "$tmp/work"
mkdir -p "$tmp/work/models/pack" "$tmp/work/other"
echo one > "$tmp/work/models/pack/a.glb"
echo other > "$tmp/work/other/b.glb"
git_ -C "$tmp/work" add -A
git_ -C "$tmp/work" commit -q -m first
first=$(git -C "$tmp/work" rev-parse HEAD)
echo two > "$tmp/work/models/pack/a.glb"
git_ -C "$tmp/work" commit -q -am second
second=$(git -C "$tmp/work" rev-parse HEAD)
mkdir -p "$tmp/mirror"
git clone -q --bare "$tmp/work" "$tmp/mirror/owner+name.git"

config() {  # config <file> <commit> [second source commit]
  {
    echo "sources:"
    echo "  - {type: folder, repository: owner/name, commit: $2, path: models, include: ['pack/*.glb']}"
    if [[ -n "${3:-}" ]]; then
      echo "  - {type: folder, repository: owner/name, commit: $3, path: other}"
    fi
    echo "output: unused.h5"
  } > "$1"
}
export SKINLAB_DATA_DIR="$tmp/data"
export SKINLAB_GIT_URL="file://$tmp/mirror/{owner}+{name}.git"
dest="$SKINLAB_DATA_DIR/owner/name"

# The first commit (not a branch tip), only the source's paths.
config "$tmp/c.yaml" "$first"
out=$("$fetch" "$tmp/c.yaml" 2>&1) || fail "fetch_data failed: $out"
expect_in "$out" "fetching $first" "owner/name at $first"
[[ $(git -C "$dest" rev-parse HEAD) == "$first" ]] || fail "HEAD is not $first"
[[ $(cat "$dest/models/pack/a.glb") == one ]] || fail "models/pack/a.glb is not the first version"
[[ ! -e "$dest/other/b.glb" ]] || fail "other/b.glb was checked out, but no source reads it"

# Again: nothing fetched.
out=$("$fetch" "$tmp/c.yaml" 2>&1) || fail "second fetch_data failed: $out"
expect_in "$out" "already at $first"

# A config at the second commit moves the folder there.
config "$tmp/c.yaml" "$second"
out=$("$fetch" "$tmp/c.yaml" 2>&1) || fail "fetch_data to $second failed: $out"
[[ $(git -C "$dest" rev-parse HEAD) == "$second" ]] || fail "HEAD is not $second"
[[ $(cat "$dest/models/pack/a.glb") == two ]] || fail "models/pack/a.glb is not the second version"

# A commit the repository does not have.
config "$tmp/bad.yaml" deadbeefdeadbeefdeadbeefdeadbeefdeadbeef
if out=$("$fetch" "$tmp/bad.yaml" 2>&1); then fail "a missing commit was accepted"; fi
expect_in "$out" "cannot fetch commit deadbeefdeadbeefdeadbeefdeadbeefdeadbeef" "owner+name.git"

# Two sources of one repository at different commits.
config "$tmp/two.yaml" "$first" "$second"
if out=$("$fetch" "$tmp/two.yaml" 2>&1); then fail "conflicting commits were accepted"; fi
expect_in "$out" "two.yaml: sources[1]" "owner/name at commit $second" "names commit $first"

# A commit that is not 40 hex digits, a config without repositories, a missing config.
config "$tmp/short.yaml" abc123
if out=$("$fetch" "$tmp/short.yaml" 2>&1); then fail "a short commit was accepted"; fi
expect_in "$out" "short.yaml: sources[0]" "commit 'abc123' is not 40 lowercase hex digits"
printf 'sources:\n  - {type: folder, path: /x}\n' > "$tmp/none.yaml"
if out=$("$fetch" "$tmp/none.yaml" 2>&1); then fail "a config without repositories was accepted"; fi
expect_in "$out" "names a 'repository'"
if out=$("$fetch" "$tmp/missing.yaml" 2>&1); then fail "a missing config was accepted"; fi
expect_in "$out" "missing.yaml: cannot read"

# A data folder that is not a checkout is not overwritten.
rm -rf "$dest"
mkdir -p "$dest" && echo mine > "$dest/file"
config "$tmp/c.yaml" "$first"
if out=$("$fetch" "$tmp/c.yaml" 2>&1); then fail "a folder that is not a checkout was overwritten"; fi
expect_in "$out" "$dest exists but is not a git checkout"
[[ $(cat "$dest/file") == mine ]] || fail "the user's file was changed"

echo "fetch_data: all checks passed"
