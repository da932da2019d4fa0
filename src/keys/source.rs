//! The scenario's types as their source declares them: each configuration struct's fields with
//! their doc comments and whether serde fills them in, each enum's variants. Read from the source
//! files compiled into the binary, so the reference says what the code that parses a scenario
//! says, in its own words.

use std::collections::BTreeMap;

/// The files that declare the scenario's types, compiled in (paths from the repository's root).
pub const FILES: &[(&str, &str)] = &[
    ("crates/run/src/scenario.rs", include_str!("../../crates/run/src/scenario.rs")),
    ("crates/control/src/config.rs", include_str!("../../crates/control/src/config.rs")),
    ("crates/control/src/pid.rs", include_str!("../../crates/control/src/pid.rs")),
    ("crates/control/src/feedforward.rs", include_str!("../../crates/control/src/feedforward.rs")),
    ("crates/control/src/slip_margin.rs", include_str!("../../crates/control/src/slip_margin.rs")),
    ("crates/control/src/task.rs", include_str!("../../crates/control/src/task.rs")),
    ("crates/control/src/settle.rs", include_str!("../../crates/control/src/settle.rs")),
    ("crates/control/src/hold.rs", include_str!("../../crates/control/src/hold.rs")),
    ("crates/run/src/detector.rs", include_str!("../../crates/run/src/detector.rs")),
    ("crates/control/src/trajectory.rs", include_str!("../../crates/control/src/trajectory.rs")),
    ("crates/control/src/slip.rs", include_str!("../../crates/control/src/slip.rs")),
    ("crates/cell/src/gripper.rs", include_str!("../../crates/cell/src/gripper.rs")),
    ("crates/cell/src/phase.rs", include_str!("../../crates/cell/src/phase.rs")),
    ("crates/fbg/src/estimate.rs", include_str!("../../crates/fbg/src/estimate.rs")),
    ("crates/fbg/src/hysteresis.rs", include_str!("../../crates/fbg/src/hysteresis.rs")),
    ("crates/fbg/src/config.rs", include_str!("../../crates/fbg/src/config.rs")),
    ("crates/fbg/src/array.rs", include_str!("../../crates/fbg/src/array.rs")),
    ("crates/twin/src/sim.rs", include_str!("../../crates/twin/src/sim.rs")),
    ("crates/twin/src/wrist.rs", include_str!("../../crates/twin/src/wrist.rs")),
    ("crates/twin/src/disturbance.rs", include_str!("../../crates/twin/src/disturbance.rs")),
    ("crates/twin/src/physics/config.rs", include_str!("../../crates/twin/src/physics/config.rs")),
    ("crates/twin/src/physics/produce_config.rs", include_str!("../../crates/twin/src/physics/produce_config.rs")),
    ("crates/drivers/src/config.rs", include_str!("../../crates/drivers/src/config.rs")),
    ("crates/hyperion/src/fbg_map.rs", include_str!("../../crates/hyperion/src/fbg_map.rs")),
    ("crates/ros2/src/config.rs", include_str!("../../crates/ros2/src/config.rs")),
];

/// One field of a struct.
#[derive(Debug, Clone)]
pub struct Field {
    /// Its key (the field's name).
    pub name: String,
    /// Its Rust type as written.
    pub ty: String,
    /// Its doc comment, lines joined.
    pub doc: String,
    /// Whether serde fills it in when the file leaves it out.
    pub defaulted: bool,
}

/// A struct's fields, or an enum's variants.
#[derive(Debug, Clone)]
pub enum Item {
    /// A struct: its fields, in order.
    Struct {
        /// The struct's own doc comment.
        doc: String,
        /// Its fields.
        fields: Vec<Field>,
    },
    /// An enum: its variants, as (name as written in TOML, the type a variant carries, doc).
    Enum(Vec<(String, Option<String>, String)>),
}

/// Every `pub struct` and `pub enum` of [`FILES`], by name (with the file it is in).
pub fn items() -> BTreeMap<String, (&'static str, Item)> {
    let mut out = BTreeMap::new();
    for (file, text) in FILES {
        for (name, item) in parse(text) {
            out.insert(name, (*file, item));
        }
    }
    out
}

/// The top-level `pub struct` and `pub enum` items of one file.
fn parse(text: &str) -> Vec<(String, Item)> {
    let mut out = Vec::new();
    let mut doc = Vec::new();
    let mut attrs = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        if let Some(d) = line.strip_prefix("///") {
            doc.push(d.trim().to_string());
        } else if line.starts_with("#[") {
            attrs.push_str(&whole_attribute(line, &mut lines));
        } else if let Some(rest) = line.strip_prefix("pub struct ").filter(|r| r.trim_end().ends_with('{')) {
            let name = ident(rest);
            let container_default = serde_default(&attrs);
            let fields = struct_fields(&mut lines, container_default);
            out.push((name, Item::Struct { doc: doc.join(" "), fields }));
        } else if let Some(rest) = line.strip_prefix("pub enum ").filter(|r| r.trim_end().ends_with('{')) {
            let name = ident(rest);
            let variants = enum_variants(&mut lines, snake_case(&attrs));
            out.push((name, Item::Enum(variants)));
        }
        if !line.starts_with("///") && !line.starts_with("#[") {
            doc.clear();
            attrs.clear();
        }
    }
    out
}

/// An attribute that may span lines (`#[serde(\n ...\n)]`), whole.
fn whole_attribute<'a>(first: &str, lines: &mut impl Iterator<Item = &'a str>) -> String {
    let mut attr = first.trim().to_string();
    while attr.matches('[').count() > attr.matches(']').count() {
        match lines.next() {
            Some(l) => attr.push_str(l.trim()),
            None => break,
        }
    }
    attr
}

/// The identifier at the start of `text`.
fn ident(text: &str) -> String {
    text.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect()
}

/// Whether serde attributes say `default` (for the container or a field).
fn serde_default(attrs: &str) -> bool {
    attrs.split("#[").any(|a| {
        a.starts_with("serde(")
            && a.trim_start_matches("serde(").split([',', ')']).any(|p| {
                let p = p.trim();
                p == "default" || p.starts_with("default =") || p.starts_with("default=")
            })
    })
}

/// Whether the enum's variants are written in snake case in TOML.
fn snake_case(attrs: &str) -> bool {
    attrs.contains("rename_all = \"snake_case\"") || attrs.contains("rename_all = \"lowercase\"")
}

fn struct_fields<'a>(
    lines: &mut std::iter::Peekable<impl Iterator<Item = &'a str>>,
    container_default: bool,
) -> Vec<Field> {
    let mut fields = Vec::new();
    let mut doc = Vec::new();
    let mut attrs = String::new();
    while let Some(line) = lines.next() {
        let l = line.trim();
        if line.starts_with('}') {
            break;
        } else if let Some(d) = l.strip_prefix("///") {
            doc.push(d.trim().to_string());
        } else if l.starts_with("#[") {
            attrs.push_str(&whole_attribute(l, lines));
        } else if let Some(rest) = l.strip_prefix("pub ") {
            if let Some((name, ty)) = rest.split_once(':') {
                fields.push(Field {
                    name: name.trim().to_string(),
                    ty: ty.trim().trim_end_matches(',').trim().to_string(),
                    doc: doc.join(" "),
                    defaulted: container_default || serde_default(&attrs),
                });
            }
            doc.clear();
            attrs.clear();
        }
    }
    fields
}

fn enum_variants<'a>(
    lines: &mut std::iter::Peekable<impl Iterator<Item = &'a str>>,
    snake: bool,
) -> Vec<(String, Option<String>, String)> {
    let mut variants = Vec::new();
    let mut doc = Vec::new();
    let mut depth = 0usize;
    for line in lines.by_ref() {
        let l = line.trim();
        if line.starts_with('}') {
            break;
        }
        if depth == 0 {
            if let Some(d) = l.strip_prefix("///") {
                doc.push(d.trim().to_string());
            } else if l.chars().next().is_some_and(char::is_uppercase) {
                let name = ident(l);
                let carried =
                    l[name.len()..].strip_prefix('(').and_then(|r| r.split_once(')')).map(|(t, _)| t.to_string());
                let written = if snake { to_snake(&name) } else { name.clone() };
                variants.push((written, carried, doc.join(" ")));
                doc.clear();
            }
        }
        depth = (depth + l.matches('{').count()).saturating_sub(l.matches('}').count());
    }
    variants
}

/// `SlipMargin` → `slip_margin`.
fn to_snake(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('_');
        }
        out.extend(c.to_lowercase());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_docs_and_defaults_are_read() {
        let items = parse(
            "/// A section.\n#[derive(Deserialize)]\n#[serde(deny_unknown_fields)]\npub struct A {\n    /// Gain [N].\n    \
             /// More.\n    pub kp: f64,\n    #[serde(\n        default = \"x\"\n    )]\n    pub ki: Option<f64>,\n}\n\
             #[serde(rename_all = \"snake_case\")]\npub enum B {\n    /// One.\n    SlipMargin(C),\n    Two,\n}\n",
        );
        let Item::Struct { fields, .. } = &items[0].1 else { panic!() };
        assert_eq!(
            (fields[0].name.as_str(), fields[0].doc.as_str(), fields[0].defaulted),
            ("kp", "Gain [N]. More.", false)
        );
        assert_eq!((fields[1].ty.as_str(), fields[1].defaulted), ("Option<f64>", true));
        let Item::Enum(v) = &items[1].1 else { panic!() };
        assert_eq!(v[0], ("slip_margin".into(), Some("C".into()), "One.".into()));
        assert_eq!(v[1].0, "two");
    }
}
