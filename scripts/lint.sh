#!/usr/bin/env bash
# Lint: ruff (ruff.toml) over every Python file, clang-format (.clang-format)
# over the C++ of native/, tests/native/ and bench/, and no pointer to a
# document outside the repo. Needs the tools of requirements.txt in .venv
# (scripts/setup.sh). Prints what is wrong and exits 1; `--fix` rewrites.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bin=.venv/bin
fix=0
[[ "${1:-}" == "--fix" ]] && fix=1
status=0

mapfile -t cxx < <(git ls-files 'native/*.cpp' 'native/*.h' 'tests/native/*.cpp' 'tests/native/*.h' \
                                 'bench/*.cpp' 'bench/*.h')
if ((fix)); then
  "$bin/ruff" check --fix -q . || status=1
  "$bin/clang-format" -i "${cxx[@]}"
else
  "$bin/ruff" check -q . || status=1
  "$bin/clang-format" --dry-run --Werror "${cxx[@]}" || { echo "lint: run scripts/lint.sh --fix"; status=1; }
fi

# Code and docs must not point at files users do not have.
if git grep -nE '(^|[^/A-Za-z])(NOTES|DESIGN)\.md|/tmp/''issue' -- native addon osl bench tests scripts docs README.md \
   ':!scripts/lint.sh'; then
  echo "lint: the lines above point at documents that are not in the repo (put the facts in docs/)"
  status=1
fi
exit $status
