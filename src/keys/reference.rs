//! The scenario key reference (`tendril keys`, shipped as `docs/guide/scenario-keys.md`): every
//! key of a pick-and-place scenario with its unit, default, bounds and meaning, generated from the
//! code that reads a scenario. The keys and meanings come from the types' declarations
//! ([`super::source`]), the defaults from scenarios the parser itself completes, the bounds from
//! the validation the loader runs ([`tendril_config::Checker::rules`]).
//! `tests/scenario_keys.rs` fails when the shipped page and this output disagree.

use super::source::{Field, Item, items};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use tendril_config::{Checker, Validate};
use tendril_run::scenario::PickPlaceScenario;

/// The smallest scenario: only the keys without a default (and the object, a section the file
/// must have). The defaults the reference shows are what the loader fills in around it.
const MINIMAL: &str = "name = \"reference\"\nsetpoint_n = 0.6\n";
const MINIMAL_OBJECT: &str = "[object]\nname = \"crimper\"\n";

/// Sections that are off or of another kind by default, switched on so that their defaults and
/// bounds are read too (their required keys get a value here, and show as required).
const SWITCHED_ON: &[&str] = &[
    "[controller]\ntype = \"feedforward\"\n",
    "[controller]\ntype = \"slip_margin\"\n",
    "[disturbance.push]\nimpulse_n_s = 0.3\nphase = \"lift\"\n[disturbance.dropout]\nduration_s = 0.5\nphase = \"lift\"\n",
    "[object]\nname = \"crimper\"\nfriction = 1.0\nposition_m = [0.0, 0.0]\nmass_kg = 0.1\nyaw_deg = 0.0\n",
    "[produce]\nmodulus_pa = 5e5\npoisson = 0.45\nbruise_pa = 1.5e5\ndetach_n = 6.0\ncount = 7\ndof = \"trilinear\"\n",
    "[array]\n[[array.pads]]\narc_m = 0.012\nlambda1_nm = 1520.0\nlambda2_nm = 1530.0\n",
    "[detector]\ntable = \"object-table.toml\"\n",
];

/// One key of the reference.
struct Row {
    /// The heading of the table it goes in.
    section: String,
    /// For the keys of one kind of a tagged section: `type`'s value.
    kind: Option<String>,
    key: String,
    unit: String,
    default: String,
    bounds: String,
    meaning: String,
}

/// What one completed scenario says: its keys' values and the bounds checked on them.
struct Instance {
    values: BTreeMap<String, serde_json::Value>,
    rules: BTreeMap<String, BTreeSet<String>>,
}

/// The reference as Markdown.
pub fn markdown() -> Result<String, String> {
    let items = items();
    let mut instances = Vec::new();
    for extra in std::iter::once("").chain(SWITCHED_ON.iter().copied()) {
        let object = if extra.contains("[object]") { "" } else { MINIMAL_OBJECT };
        let text = format!("{MINIMAL}{object}{extra}");
        let scenario: PickPlaceScenario = tendril_config::from_str(&text, Path::new("scenarios/reference.toml"), &[])
            .map_err(|e| format!("the reference's own scenario does not load: {e}"))?;
        let mut at = Checker::default();
        scenario.validate(&mut at);
        let mut rules: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (key, rule) in at.rules() {
            rules.entry(key.clone()).or_default().insert(rule.clone());
        }
        let mut value = serde_json::to_value(&scenario).map_err(|e| e.to_string())?;
        // `[ros2]` is recorded only when it differs from its defaults (a run without it writes
        // what it always wrote): its defaults are read from the section itself.
        if let Some(fields) = value.as_object_mut() {
            let ros2 = serde_json::to_value(&scenario.ros2).map_err(|e| e.to_string())?;
            fields.entry("ros2").or_insert(ros2);
        }
        let mut flat = Vec::new();
        flatten("", &value, &mut flat);
        instances.push(Instance { values: flat.into_iter().collect(), rules });
    }
    let mut rows = Vec::new();
    walk(&items, "PickPlaceScenario", "", "Top level", &mut rows)?;
    let written: BTreeSet<&str> = rows.iter().map(|r| r.key.as_str()).collect();
    for key in instances.iter().flat_map(|i| i.values.keys()) {
        // An optional section left out serialises as its own key (`estimator.hysteresis = null`).
        let section = format!("{key}.");
        if !written.contains(key.as_str()) && !written.iter().any(|w| w.starts_with(&section)) {
            return Err(format!("key `{key}` is in a scenario but not found in the source's types"));
        }
    }
    // A key another kind of the section documents with its unit ("as `PidConfig::kp`").
    let units: BTreeMap<String, String> =
        rows.iter().filter(|r| r.unit != "-").map(|r| (r.key.clone(), r.unit.clone())).collect();
    for row in &mut rows {
        if row.unit == "-"
            && let Some(unit) = units.get(&row.key)
        {
            row.unit = unit.clone();
        }
        // The instance of the row's kind (`controller.type`), else the first that has the key.
        let of_kind = |i: &&Instance| match &row.kind {
            Some(kind) => i.values.get(&kind_key(&row.key)) == Some(&serde_json::Value::String(kind.clone())),
            None => i.values.contains_key(&row.key) || i.rules.contains_key(&row.key),
        };
        let instance = instances.iter().find(of_kind);
        if row.default.is_empty() {
            row.default = instance.and_then(|i| i.values.get(&row.key)).map(show).unwrap_or_else(|| "none".into());
        }
        if let Some(rules) = instance.and_then(|i| i.rules.get(&row.key)) {
            let rules: Vec<&str> = rules.iter().map(String::as_str).collect();
            row.bounds =
                if row.bounds.is_empty() { rules.join(", ") } else { format!("{}; {}", row.bounds, rules.join(", ")) };
        }
    }
    Ok(render(&rows))
}

/// `controller.kp` → `controller.type`.
fn kind_key(key: &str) -> String {
    match key.rsplit_once('.') {
        Some((section, _)) => format!("{section}.type"),
        None => "type".into(),
    }
}

/// The keys of `type_name` under `prefix`, in declaration order, nested sections after their
/// parent's plain keys.
fn walk(
    items: &BTreeMap<String, (&str, Item)>,
    type_name: &str,
    prefix: &str,
    section: &str,
    rows: &mut Vec<Row>,
) -> Result<(), String> {
    let Some((_, item)) = items.get(type_name) else {
        return Err(format!("type `{type_name}` (at `{prefix}`) is not declared in the files keys::source reads"));
    };
    let Item::Struct { fields, .. } = item else {
        return Err(format!("type `{type_name}` (at `{prefix}`) is not a struct"));
    };
    let mut nested = Vec::new();
    for field in fields {
        let key = format!("{prefix}{}", field.name);
        let inner = unwrap_type(&field.ty);
        match items.get(inner).map(|(_, i)| i) {
            Some(Item::Struct { .. }) => nested.push((key, inner, field)),
            Some(Item::Enum(variants)) if variants.iter().any(|(_, carried, _)| carried.is_some()) => {
                nested.push((key, inner, field));
            }
            Some(Item::Enum(variants)) => {
                let names: Vec<String> = variants.iter().map(|(n, _, _)| format!("`\"{n}\"`")).collect();
                rows.push(leaf(section, &key, field, Some(names.join(", "))));
            }
            None => rows.push(leaf(section, &key, field, None)),
        }
    }
    for (key, inner, field) in nested {
        let heading = format!("`[{key}]`: {}", clean(&field.doc));
        match &items[inner].1 {
            Item::Enum(variants) => {
                // An internally tagged section (`[controller]`): `type`, then each kind's keys.
                let names: Vec<String> = variants.iter().map(|(n, _, _)| format!("`\"{n}\"`")).collect();
                rows.push(Row {
                    section: heading.clone(),
                    kind: None,
                    key: format!("{key}.type"),
                    unit: "-".into(),
                    default: String::new(),
                    bounds: names.join(", "),
                    meaning: "The kind of section; the other keys depend on it.".into(),
                });
                for (name, carried, doc) in variants {
                    let Some(carried) = carried else { continue };
                    let start = rows.len();
                    // The variant's doc starts by naming itself (`type = "pid"`: ...).
                    let doc = clean(doc);
                    let doc = doc
                        .split_once("`: ")
                        .filter(|(head, _)| head.contains("type ="))
                        .map_or(doc.as_str(), |(_, d)| d);
                    let heading = format!("`[{key}]` with `type = \"{name}\"`: {doc}");
                    walk(items, carried, &format!("{key}."), &heading, rows)?;
                    for row in &mut rows[start..] {
                        row.kind = Some(name.clone());
                    }
                }
            }
            Item::Struct { .. } => walk(items, inner, &format!("{key}."), &heading, rows)?,
        }
    }
    Ok(())
}

fn leaf(section: &str, key: &str, field: &Field, values: Option<String>) -> Row {
    let optional = field.ty.starts_with("Option<");
    let default = if optional {
        // Absent unless given (the key's own default, whatever a switched-on section holds).
        "none".to_string()
    } else if !field.defaulted {
        "required".to_string()
    } else if field.ty.contains("PathBuf") {
        "see meaning".to_string()
    } else if field.ty.starts_with("Vec<")
        && field.ty[4..].starts_with(char::is_uppercase)
        && !field.ty.contains("String")
    {
        // A list of tables (`[[array.pads]]`): empty unless given; a switched-on section's
        // example entries are not its default.
        "`[]`".to_string()
    } else {
        String::new()
    };
    Row {
        section: section.to_string(),
        kind: None,
        key: key.to_string(),
        unit: unit(field),
        default,
        bounds: values.unwrap_or_default(),
        meaning: clean(&field.doc),
    }
}

/// `Option<Box<T>>` → `T`.
fn unwrap_type(ty: &str) -> &str {
    let mut t = ty.trim();
    for wrapper in ["Option<", "Box<"] {
        if let Some(inner) = t.strip_prefix(wrapper) {
            t = inner.strip_suffix('>').unwrap_or(inner).trim();
        }
    }
    t
}

/// Units named by a key's ending, for the docs that give none in brackets (longest first).
const SUFFIX_UNITS: &[(&str, &str)] = &[
    ("_deg_s2", "°/s²"),
    ("_deg_s", "°/s"),
    ("_rad_s", "rad/s"),
    ("_m_s", "m/s"),
    ("_nm", "nm"),
    ("_pm", "pm"),
    ("_hz", "Hz"),
    ("_kg", "kg"),
    ("_deg", "°"),
    ("_s", "s"),
    ("_n", "N"),
    ("_m", "m"),
];

/// The unit a field's doc gives in brackets (`[N]`, `\[m/s\]`, `[-]`), else the one its name ends
/// with (`_nm`), else `-`.
fn unit(field: &Field) -> String {
    let doc = field.doc.replace('\\', "");
    let mut rest = doc.as_str();
    while let Some(open) = rest.find('[') {
        let after = &rest[open + 1..];
        let Some(close) = after.find(']') else { break };
        let inside = &after[..close];
        let is_link = after[close + 1..].starts_with('(') || inside.starts_with('`');
        if !is_link && !inside.is_empty() && inside.chars().count() <= 12 && !inside.contains(", ") {
            return inside.to_string();
        }
        rest = &after[close + 1..];
    }
    SUFFIX_UNITS.iter().find(|(suffix, _)| field.name.ends_with(suffix)).map_or("-", |(_, unit)| unit).to_string()
}

/// A doc comment as table text: rustdoc escapes and intra-doc link brackets removed, `|` escaped.
fn clean(doc: &str) -> String {
    let mut text = doc.replace("\\[", "[").replace("\\]", "]").replace('|', "\\|");
    // [`Name`] and [`Name`](path) links of rustdoc: keep the code span.
    while let Some(i) = text.find("[`") {
        let Some(j) = text[i..].find("`]").map(|j| i + j) else { break };
        let code = text[i + 1..j + 1].to_string();
        let mut end = j + 2;
        if text[end..].starts_with('(')
            && let Some(k) = text[end..].find(')')
        {
            end += k + 1;
        }
        text.replace_range(i..end, &code);
    }
    text
}

/// A default value as TOML writes it.
fn show(value: &serde_json::Value) -> String {
    match value {
        serde_json::Value::Null => "none".into(),
        serde_json::Value::String(s) => format!("`\"{s}\"`"),
        other => format!("`{other}`").replace(',', ", "),
    }
}

fn flatten(prefix: &str, value: &serde_json::Value, out: &mut Vec<(String, serde_json::Value)>) {
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                flatten(&key, v, out);
            }
        }
        other => out.push((prefix.to_string(), other.clone())),
    }
}

fn render(rows: &[Row]) -> String {
    let mut out = String::from(
        "# Scenario keys\n\n\
         Every key of a pick-and-place scenario (`tendril run`, `view`, `sweep`, `serve`, ...), with\n\
         its unit, its default, the bounds the loader checks and its meaning. Generated from the code\n\
         by `tendril keys` (do not edit: `tendril keys > docs/guide/scenario-keys.md` rewrites it, and\n\
         `tests/scenario_keys.rs` fails when the two disagree). Keys are written as `--set` takes\n\
         them; in a file, `physics.timestep_s = 0.002` is `timestep_s = 0.002` under `[physics]`.\n\
         `required`: the file must give it. `none`: off, or taken from the model, when absent.\n\
         Bounds are the allowed values and the range checks; some keys have further checks\n\
         (between keys, against the model), reported by key when they fail.\n",
    );
    let mut current = None;
    for row in rows {
        if current != Some(&row.section) {
            current = Some(&row.section);
            out.push_str(&format!("\n## {}\n\n", row.section));
            out.push_str("| key | unit | default | bounds | meaning |\n| --- | --- | --- | --- | --- |\n");
        }
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            row.key, row.unit, row.default, row.bounds, row.meaning
        ));
    }
    out
}
