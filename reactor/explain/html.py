"""One self-contained HTML page for an explanation: Python, IR and assembly in three linked columns.

Hovering a source line (or any of its instructions) highlights the line and all its
instructions in the three columns; each source line shows its cost. With a diff, a
table of the two builds' machine operations per line follows, the changed lines
marked. No network: styles and script are inline. Opening the page with
``#selftest`` runs a check in the page itself (it hovers the first source line and
counts what lit up) and writes the result as JSON into ``<pre id="selftest">``, so a
headless browser can test the page (tests/explain).
"""
from __future__ import annotations

import html
import json

from ..cost.lines import runs_text, summary_text

_STYLE = """
body { font: 13px/1.35 system-ui, sans-serif; margin: 0; color: #222; }
header { padding: 8px 14px; background: #f3f3f3; border-bottom: 1px solid #ccc; }
header h1 { font-size: 16px; margin: 0 0 4px 0; }
#columns { display: grid; grid-template-columns: 1fr 1.3fr 1fr; gap: 0; }
section.col { border-right: 1px solid #ddd; overflow-x: auto; }
section.col h2 { font-size: 13px; margin: 0; padding: 6px 10px; background: #fafafa; border-bottom: 1px solid #ddd;
  position: sticky; top: 0; }
.row { padding: 3px 10px; border-bottom: 1px solid #eee; cursor: default; }
.group { padding: 3px 10px; background: #f7f7fb; color: #555; font-size: 12px; border-top: 1px solid #e4e4ee; }
.ins { font: 12px/1.3 ui-monospace, monospace; white-space: pre; padding: 0 10px; }
.where { color: #777; font-size: 11px; margin-right: 6px; }
.cost { color: #555; font-size: 11px; display: block; }
.critical { color: #b00; }
code { font: 12px ui-monospace, monospace; }
.hl { background: #fff2a8 !important; }
.routine { color: #2b5fb3; }
table.diff { border-collapse: collapse; margin: 10px 14px; }
table.diff td, table.diff th { border: 1px solid #ddd; padding: 3px 6px; font-size: 12px; vertical-align: top; }
table.diff tr.changed td { background: #fde8e8; }
"""

_SCRIPT = """
(function () {
  var errors = [];
  window.addEventListener('error', function (e) { errors.push(String(e.message)); });
  function light(key, on) {
    document.querySelectorAll('[data-key]').forEach(function (el) {
      if (el.dataset.key === key) { el.classList.toggle('hl', on); }
    });
  }
  document.querySelectorAll('[data-key]').forEach(function (el) {
    el.addEventListener('mouseenter', function () { light(el.dataset.key, true); });
    el.addEventListener('mouseleave', function () { light(el.dataset.key, false); });
  });
  if (location.hash === '#selftest') {
    var first = document.querySelector('#source .row[data-key]');
    var result = {errors: errors, columns: document.querySelectorAll('section.col').length};
    if (first) {
      first.dispatchEvent(new MouseEvent('mouseenter'));
      result.key = first.dataset.key;
      result.ir = document.querySelectorAll('#ir .ins.hl').length;
      result.asm = document.querySelectorAll('#asm .ins.hl').length;
      result.ir_total = document.querySelectorAll('#ir .ins[data-key="' + first.dataset.key + '"]').length;
      result.asm_total = document.querySelectorAll('#asm .ins[data-key="' + first.dataset.key + '"]').length;
      first.dispatchEvent(new MouseEvent('mouseleave'));
      result.after = document.querySelectorAll('.hl').length;
    }
    var out = document.getElementById('selftest');
    out.textContent = JSON.stringify(result);
    out.hidden = false;
  }
})();
"""


def _e(text: str) -> str:
    return html.escape(text, quote=True)


def _cost(row) -> str:
    if not row.cost:
        return ""
    ops = ", ".join(f"{n} {c}" for c, n in sorted(row.cost["ops"].items(), key=lambda kv: -kv[1]))
    crit = ' <span class="critical">critical path</span>' if row.cost["critical"] else ""
    return f'<span class="cost">{_e(ops + runs_text(row.cost))}; {row.cost["share"]:.0%} of the work{crit}</span>'


def page(explanation, diff=None) -> str:
    """The page of ``explanation`` (and of ``diff``, a ``Diff``, if given)."""
    e = explanation
    head = f"<h1>{_e(e.name)}</h1><div>{_e(e.settings)}</div>"
    if e.costs:
        head += f"<div>{_e(summary_text(e.costs))}</div>"
    head += "".join(f'<div class="loop">{_e(lp.text())}</div>' for lp in getattr(e, "loops", []))
    source: list[str] = []
    ir: list[str] = []
    asm: list[str] = []
    for row in e.lines:
        key = _e(row.key)
        label = _e(row.label)
        cls = " routine" if row.group else ""
        source.append(f'<div class="row{cls}" data-key="{key}"><span class="where">{label}</span>'
                      f'<code>{_e(row.source.strip())}</code>{_cost(row)}</div>')
        for column, items in ((ir, row.ir), (asm, row.asm)):
            column.append(f'<div class="group{cls}" data-key="{key}">{label}</div>')
            column.extend(f'<div class="ins" data-key="{key}">{_e(i.text)}</div>' for i in items)
    columns = (f'<div id="columns"><section class="col" id="source"><h2>Python</h2>{"".join(source)}</section>'
               f'<section class="col" id="ir"><h2>LLVM IR (optimized)</h2>{"".join(ir)}</section>'
               f'<section class="col" id="asm"><h2>Assembly</h2>{"".join(asm)}</section></div>')
    return ("<!doctype html><html><head><meta charset=\"utf-8\">"
            f"<title>{_e(e.name)}: explain</title><style>{_STYLE}</style></head><body>"
            f"<header>{head}</header>{columns}{_diff(diff)}"
            f'<pre id="selftest" hidden></pre><script>{_SCRIPT}</script></body></html>')


def _diff(diff) -> str:
    if diff is None:
        return ""
    rows = []
    for a, b in diff.rows:
        row = a or b
        ops_a, ops_b = diff._ops(a), diff._ops(b)
        cls = ' class="changed"' if ops_a != ops_b else ""
        fmt = lambda ops: _e(", ".join(f"{n} {op}" if n > 1 else op for op, n in sorted(ops.items())))  # noqa: E731
        rows.append(f'<tr{cls} data-key="{_e(row.key)}"><td>{_e(row.label)}</td><td><code>{_e(row.source.strip())}'
                    f'</code></td><td>{sum(ops_a.values())}: {fmt(ops_a)}</td><td>{sum(ops_b.values())}: '
                    f'{fmt(ops_b)}</td></tr>')
    return (f'<section id="diff"><h2 style="margin:10px 14px 0">Diff</h2>'
            f'<div style="margin:4px 14px">A: {_e(diff.a.settings)}<br>B: {_e(diff.b.settings)}</div>'
            f'<table class="diff"><tr><th>line</th><th>Python</th><th>A</th><th>B</th></tr>{"".join(rows)}'
            f"</table></section>")


def selftest_result(dom: str) -> dict:
    """The JSON a page wrote into ``#selftest`` (from a browser's dumped DOM)."""
    start = dom.index('id="selftest"')
    body = dom[dom.index(">", start) + 1:dom.index("</pre>", start)]
    return json.loads(html.unescape(body))
