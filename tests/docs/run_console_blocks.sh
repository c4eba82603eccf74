#!/usr/bin/env bash
# ctest case docs_commands: runs every command shown in a ```console block of README.md and
# docs/*.md against the built ffsr-optimize, so the commands in the docs cannot rot.
#
#   bash tests/docs/run_console_blocks.sh PATH/TO/ffsr-optimize SOURCE_DIR [FILE.md ...]
#
# In a ```console block:
#   - a line starting with "$ " is a command; a command ending in "\" continues on the next line;
#   - a line "# exit N" says that the command before it must exit with status N (default 0);
#   - every other line is output shown to the reader and is not checked.
# Each command runs with bash from one scratch folder that holds a link "robots" to SOURCE_DIR/robots
# (the docs' commands are written from the repository's root), and with "ffsr-optimize" on PATH
# being the built command. A command that exits with another status than the expected one, or runs
# longer than 120 s, fails the test. ```sh blocks (builds, long runs) are not run.
set -uo pipefail

if [ $# -lt 2 ]; then
  echo "usage: $0 PATH/TO/ffsr-optimize SOURCE_DIR [FILE.md ...]" >&2
  exit 2
fi
cli="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
src="$(cd "$2" && pwd)"
shift 2
if [ ! -x "$cli" ]; then
  echo "docs_commands: $cli is not an executable" >&2
  exit 2
fi
files=("$@")
if [ ${#files[@]} -eq 0 ]; then
  files=("$src/README.md")
  for f in "$src"/docs/*.md; do files+=("$f"); done
fi

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/bin" "$scratch/work"
ln -s "$cli" "$scratch/bin/ffsr-optimize"
ln -s "$src/robots" "$scratch/work/robots"

total=0
failed=0
start_all=$(date +%s.%N)

# run_one FILE LINE EXPECTED COMMAND
run_one() {
  local file="$1" line="$2" expected="$3" cmd="$4"
  total=$((total + 1))
  local t0 t1 rc
  t0=$(date +%s.%N)
  (cd "$scratch/work" && PATH="$scratch/bin:$PATH" timeout 120 bash -c "$cmd") \
    > "$scratch/out" 2> "$scratch/err" < /dev/null
  rc=$?
  t1=$(date +%s.%N)
  local secs
  secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')
  local where="${file#"$src"/}:$line"
  if [ "$rc" -ne "$expected" ]; then
    failed=$((failed + 1))
    echo "FAIL $where (exit $rc, expected $expected, ${secs} s): \$ $cmd"
    echo "---- stdout (last 20 lines)"; tail -n 20 "$scratch/out"
    echo "---- stderr (last 20 lines)"; tail -n 20 "$scratch/err"
    echo "----"
  else
    echo "ok   $where (exit $rc, ${secs} s): \$ $cmd"
  fi
}

for file in "${files[@]}"; do
  in_block=0
  pending=""        # the last command, run when the next command, "# exit N" or the block's end comes
  pending_line=0
  continuing=0
  n=0
  while IFS= read -r text || [ -n "$text" ]; do
    n=$((n + 1))
    if [ $in_block -eq 0 ]; then
      [[ "$text" =~ ^[[:space:]]*\`\`\`console[[:space:]]*$ ]] && in_block=1
      continue
    fi
    if [ $continuing -eq 1 ]; then
      pending="${pending%\\} $text"
      [[ "$text" =~ \\$ ]] || continuing=0
      continue
    fi
    if [[ "$text" =~ ^[[:space:]]*\`\`\` ]]; then
      [ -n "$pending" ] && run_one "$file" "$pending_line" 0 "$pending"
      pending=""
      in_block=0
      continue
    fi
    if [[ "$text" =~ ^\$\ (.*)$ ]]; then
      [ -n "$pending" ] && run_one "$file" "$pending_line" 0 "$pending"
      pending="${BASH_REMATCH[1]}"
      pending_line=$n
      [[ "$pending" =~ \\$ ]] && continuing=1
      continue
    fi
    if [[ "$text" =~ ^#\ exit\ ([0-9]+)[[:space:]]*$ ]]; then
      if [ -z "$pending" ]; then
        echo "FAIL ${file#"$src"/}:$n: '# exit' with no command before it"
        failed=$((failed + 1))
      else
        run_one "$file" "$pending_line" "${BASH_REMATCH[1]}" "$pending"
        pending=""
      fi
    fi
  done < "$file"
  if [ $in_block -eq 1 ]; then
    echo "FAIL ${file#"$src"/}: a console block is not closed"
    failed=$((failed + 1))
  fi
done

secs=$(awk -v a="$start_all" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
echo "docs_commands: $total commands from ${#files[@]} files in ${secs} s, $failed failed"
if [ "$total" -eq 0 ]; then
  echo "docs_commands: no command found (expected console blocks in README.md and docs/)"
  exit 1
fi
[ "$failed" -eq 0 ]
