#!/usr/bin/env bash
# Writes the bash completion of dmc from the built tool's own --help (commands, and each
# command's options). Usage: make-completion.sh DMC OUTPUT
set -euo pipefail
dmc="$1"
out="$2"
commands=$("$dmc" --help | sed -n '/^Subcommands:/,$p' | sed -n 's/^  \([a-z][a-z]*\)  .*/\1/p')
tmp="$out.tmp"
{
  echo "# bash completion for dmc (generated from dmc --help by tools/packaging/make-completion.sh)"
  echo "_dmc() {"
  echo "  local cur=\${COMP_WORDS[COMP_CWORD]}"
  echo "  if [ \"\$COMP_CWORD\" -eq 1 ]; then"
  echo "    COMPREPLY=(\$(compgen -W \"$(echo $commands) --help --version\" -- \"\$cur\"))"
  echo "    return"
  echo "  fi"
  echo "  local options"
  echo "  case \${COMP_WORDS[1]} in"
  for command in $commands; do
    options=$("$dmc" "$command" --help | grep -o -- '--[a-z][a-z0-9-]*' | sort -u | tr '\n' ' ')
    echo "    $command) options=\"$options\" ;;"
  done
  echo "    *) options=\"\" ;;"
  echo "  esac"
  echo "  if [[ \$cur == -* ]]; then"
  echo "    COMPREPLY=(\$(compgen -W \"\$options\" -- \"\$cur\"))"
  echo "  else"
  echo "    COMPREPLY=(\$(compgen -f -- \"\$cur\"))"
  echo "  fi"
  echo "}"
  echo "complete -o filenames -F _dmc dmc"
} >"$tmp"
mv "$tmp" "$out"
