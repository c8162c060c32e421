#!/bin/sh
# Doxygen's input filter for msg/*.msg and srv/*.srv (Doxyfile, FILTER_PATTERNS): Doxygen cannot
# parse a message definition, so each becomes a Markdown page (EXTENSION_MAPPING msg=md srv=md)
# titled with the type's name and holding the definition verbatim in a code block, whose
# Python highlighting sets the `#` comments (what each field means, its unit, its range) apart
# from the fields. Verbatim, so that nothing in a comment is read as Doxygen or Markdown markup.
#   usage: doxygen_message_page.sh FILE
file=$1
name=$(basename "$file")
type=${name%.*}
case "$name" in
  *.srv) kind=service label=srv ;;
  *) kind=message label=msg ;;
esac
printf '# %s %s {#%s_%s}\n\n' "$type" "$kind" "$label" "$type"
# shellcheck disable=SC2016  # the backticks are Markdown's, not a command
printf 'The %s `collision_response/%s` (`%s/%s`), as defined: its comments say what each\n' \
  "$kind" "$type" "$label" "$name"
printf 'field means, its unit and its range.\n\n'
printf '```{.py}\n'
awk 1 "$file" # each line ended by a newline, also the last
printf '```\n'
