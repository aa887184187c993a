// The live status: merging the diffs of notify_status_update into the snapshot.

function isObj(v) { return v !== null && typeof v === "object" && !Array.isArray(v); }

/** Merge a status diff into the snapshot (nested objects merge, everything else replaces). */
export function mergeDiff(into, diff) {
  for (const [k, v] of Object.entries(diff || {})) {
    if (isObj(v) && isObj(into[k])) mergeDiff(into[k], v);
    else into[k] = isObj(v) ? structuredClone(v) : v;
  }
  return into;
}
