# Splits the fenced code blocks of one Markdown file into OUT/NNN.src with
# OUT/NNN.meta = "FILE LINE LANG MARKER..." (MARKER: the text of an
# "<!-- snippet: ... -->" comment on the line just before the fence, or
# "-"). Used by doc_snippets_test.sh:
#   awk -v doc=docs/client.md -v out=DIR -v first=N -f extract_snippets.awk FILE
BEGIN { n = first; inside = 0; marker = "-" }
/^ *```/ {
  if (inside) { inside = 0; close(src); next }
  inside = 1; lang = $0; sub(/^ *```/, "", lang); if (lang == "") lang = "untagged"
  src = sprintf("%s/%03d.src", out, n); printf "" > src
  printf "%s %d %s %s\n", doc, NR, lang, marker > sprintf("%s/%03d.meta", out, n)
  close(sprintf("%s/%03d.meta", out, n)); n++; marker = "-"; next
}
inside { print > src; next }
/^ *<!-- snippet: .* -->$/ { marker = $0; sub(/^ *<!-- snippet: /, "", marker); sub(/ -->$/, "", marker); next }
{ marker = "-" }
