"""Summarizes bench_wet JSON lines (stdin): one row per run and the totals (bench/run_wet_seeds.sh)."""
import json
import sys

rows = [json.loads(line) for line in sys.stdin if line.startswith("{")]
print("run  fibers  rounds  stable  cycling  newton_its  events  wet_newton_s  events_s  total_s  bridges  E_total")
for i, d in enumerate(rows, 1):
    s = d["seconds"]
    print(f"{i:3d}  {d['fibers']:6d}  {d['rounds']:6d}  {str(d['stable']):6s}  {str(d['cycling']):7s}  "
          f"{d['newton_iterations']:10d}  {d['events']:6d}  {s['wet_newton']:12.2f}  {s['events']:8.3f}  {s['total']:7.2f}  "
          f"{d['bridges_final']:7d}  {d.get('E_total', float('nan')):8.4f}")
its = sum(d["newton_iterations"] for d in rows)
t = sum(d["seconds"]["wet_newton"] for d in rows)
n = max(len(rows), 1)
print(f"total: {len(rows)} runs, {sum(d['stable'] for d in rows)} stable, {sum(d['cycling'] for d in rows)} cycling, "
      f"{its} Newton iterations ({its / n:.0f} per run), {t:.1f} s wet Newton ({t / n:.1f} s per run), "
      f"mean E_total {sum(d.get('E_total', float('nan')) for d in rows) / n:.4f}, "
      f"mean bridges {sum(d['bridges_final'] for d in rows) / n:.1f}")
