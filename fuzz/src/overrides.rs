//! The structured input of the `overrides` target: a base scene and
//! `key=value` overrides whose keys are mostly the base scene's real keys
//! (every default filled in) and whose values are of any type and size.

use std::sync::OnceLock;

use arbitrary::Arbitrary;
use ballcage_core::Document;

/// The base scenes, as TOML text: small drill pipes (the paper's scene with
/// one or two joints) and the example scenes.
pub const BASES: [&str; 5] = [
    "kind = \"drill-pipe\"\n[pipe]\njoints = 1\n",
    "kind = \"drill-pipe\"\n[pipe]\njoints = 2\nhinge = \"ideal-cv\"\n",
    // 5 samples per link (the default before issue 25): at a frame every
    // 1e-5 s the default 33 would record more contact slots than the 4 GB budget.
    "kind = \"drill-pipe\"\n[simulation]\nintegrator = \"rk4\"\nrtol = 0.0\ndt = 1e-7\noutput_interval = 1e-5\n[pipe]\njoints = 1\ntube_contact_points = 5\n",
    include_str!("../../examples/scenes/ball_drop.toml"),
    include_str!("../../examples/scenes/two_balls.toml"),
];

/// Overrides applied at most per input.
pub const MAX_SETS: usize = 8;

/// One fuzz input.
#[derive(Debug, Arbitrary)]
pub struct Input {
    /// Index into [`BASES`] (modulo).
    pub base: u8,
    /// Overrides, in order (the first [`MAX_SETS`]).
    pub sets: Vec<Set>,
}

/// One `key=value` override.
#[derive(Debug, Arbitrary)]
pub struct Set {
    /// The key.
    pub key: Key,
    /// The value.
    pub value: Value,
}

/// An override's key.
#[derive(Debug, Arbitrary)]
pub enum Key {
    /// A real key of the base scene (index modulo their count).
    Known(u16),
    /// A real key with a sub-key appended (into a list, a number, a missing key).
    Child(u16, u8),
    /// A real key written with `[i]` for its list indices.
    Bracketed(u16),
    /// Any text.
    Raw(String),
}

/// An override's value.
#[derive(Debug, Arbitrary)]
pub enum Value {
    /// An integer.
    Int(i64),
    /// A float (NaN and the infinities included).
    Float(f64),
    /// One of [`SPECIAL`].
    Special(u8),
    /// The base scene's own value at the key scaled by 10^e, e one of
    /// [`EXPONENTS`] (index k modulo), negated for odd k.
    Scaled(u8),
    /// A boolean.
    Bool(bool),
    /// One of [`WORDS`], quoted.
    Word(u8),
    /// A quoted string.
    Str(String),
    /// An array of floats.
    Floats(Vec<f64>),
    /// A table `{ law = WORD, stiffness = x }` or `{ type = WORD, radius = x }`.
    Tagged(bool, u8, f64),
    /// Any text, parsed as TOML (or taken as a string when it does not parse).
    Raw(String),
}

/// Numbers at the edges.
pub const SPECIAL: [&str; 20] = [
    "nan",
    "inf",
    "-inf",
    "0",
    "0.0",
    "-0.0",
    "-1",
    "1",
    "1e308",
    "-1e308",
    "5e-324",
    "1e-300",
    "1e300",
    "9007199254740993",
    "4294967296",
    "18446744073709551615",
    "-9223372036854775808",
    "1e-12",
    "0.5",
    "[]",
];

/// Every enum word of a scene document.
pub const WORDS: [&str; 44] = [
    "generic",
    "drill-pipe",
    "symplectic-euler",
    "rk4",
    "linearly-implicit-euler",
    "sdirk2",
    "block-elimination",
    "sparse-lu",
    "fixed",
    "dynamic",
    "kinematic-spin",
    "spin",
    "ball",
    "cuboid",
    "half-space",
    "cylinder",
    "tube",
    "straight",
    "arc",
    "SI",
    "N-mm-s",
    "impact",
    "lankarani-nikravesh",
    "hunt-crossley",
    "flores",
    "hertz",
    "linear",
    "adams",
    "tanh",
    "torus-ball",
    "slot-ball",
    "cavity-sphere",
    "ring-cylinder",
    "torque",
    "cv",
    "bodies",
    "contacts",
    "energy",
    "summary",
    "links",
    "hinges",
    "keys",
    "ball-keys",
    "ideal-cv",
];

const CHILDREN: [&str; 10] = ["0", "1", "2", "3", "99", "x", "law", "type", "", "mass"];

/// Every dotted key of each base scene's resolved document (tables, lists
/// and their elements, leaves), with the value there.
fn keys() -> &'static [Vec<(String, toml::Value)>] {
    static KEYS: OnceLock<Vec<Vec<(String, toml::Value)>>> = OnceLock::new();
    KEYS.get_or_init(|| {
        BASES
            .iter()
            .map(|text| {
                let doc = Document::from_toml_str(text, &[]).expect("base scene loads");
                let mut out = Vec::new();
                walk("", &doc.value("").expect("whole document"), &mut out);
                out
            })
            .collect()
    })
}

fn walk(prefix: &str, v: &toml::Value, out: &mut Vec<(String, toml::Value)>) {
    let join = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match v {
        toml::Value::Table(t) => {
            for (k, child) in t {
                out.push((join(k), child.clone()));
                walk(&join(k), child, out);
            }
        }
        toml::Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                out.push((join(&i.to_string()), child.clone()));
                walk(&join(&i.to_string()), child, out);
            }
        }
        _ => {}
    }
}

/// A float as TOML (`nan`, `inf`, `1e-7`, `0.5`).
fn float(x: f64) -> String {
    if x.is_nan() {
        "nan".to_string()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        format!("{x:?}")
    }
}

/// A string as a TOML basic string.
fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// Powers of ten a base value is scaled by: near it, and far enough to
/// overflow or underflow what is derived from it (r³, r⁵).
pub const EXPONENTS: [i32; 29] = [
    -300, -200, -100, -30, -10, -9, -8, -7, -6, -5, -4, -3, -2, -1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9,
    10, 30, 100, 200, 300,
];

fn scaled(base: &toml::Value, k: u8) -> String {
    let e = EXPONENTS[usize::from(k) % EXPONENTS.len()];
    let factor = 10f64.powi(e) * if k % 2 == 1 { -1.0 } else { 1.0 };
    match base {
        toml::Value::Float(x) => float(x * factor),
        toml::Value::Integer(i) => float(*i as f64 * factor),
        toml::Value::Array(a) => {
            let items: Vec<String> = a.iter().map(|v| scaled(v, k)).collect();
            format!("[{}]", items.join(", "))
        }
        other => other.to_string(),
    }
}

impl Input {
    /// The base scene's TOML and the overrides as `key=value` strings.
    pub fn render(&self) -> (&'static str, Vec<String>) {
        let b = usize::from(self.base) % BASES.len();
        let keys = &keys()[b];
        let pick = |i: u16| &keys[usize::from(i) % keys.len()];
        let sets = self.sets.iter().take(MAX_SETS).map(|s| {
            let (key, base) = match &s.key {
                Key::Known(i) => (pick(*i).0.clone(), Some(&pick(*i).1)),
                Key::Child(i, c) => (
                    format!(
                        "{}.{}",
                        pick(*i).0,
                        CHILDREN[usize::from(*c) % CHILDREN.len()]
                    ),
                    None,
                ),
                Key::Bracketed(i) => (bracketed(&pick(*i).0), Some(&pick(*i).1)),
                Key::Raw(k) => (k.clone(), None),
            };
            format!("{key}={}", s.value.render(base))
        });
        (BASES[b], sets.collect())
    }
}

/// `bodies.1.mass` written `bodies[1].mass`.
fn bracketed(key: &str) -> String {
    let mut out = String::new();
    for part in key.split('.') {
        if part.parse::<usize>().is_ok() {
            out.push_str(&format!("[{part}]"));
        } else {
            if !out.is_empty() {
                out.push('.');
            }
            out.push_str(part);
        }
    }
    out
}

impl Value {
    /// The value as override text; `base` is the base scene's value at the key.
    fn render(&self, base: Option<&toml::Value>) -> String {
        match self {
            Value::Int(i) => i.to_string(),
            Value::Float(x) => float(*x),
            Value::Special(i) => SPECIAL[usize::from(*i) % SPECIAL.len()].to_string(),
            Value::Scaled(k) => base.map_or_else(|| "1".to_string(), |b| scaled(b, *k)),
            Value::Bool(b) => b.to_string(),
            Value::Word(i) => quoted(WORDS[usize::from(*i) % WORDS.len()]),
            Value::Str(s) => quoted(s),
            Value::Floats(v) => {
                let items: Vec<String> = v.iter().take(8).map(|x| float(*x)).collect();
                format!("[{}]", items.join(", "))
            }
            Value::Tagged(law, w, x) => {
                let word = quoted(WORDS[usize::from(*w) % WORDS.len()]);
                if *law {
                    format!("{{ law = {word}, stiffness = {} }}", float(*x))
                } else {
                    format!("{{ type = {word}, radius = {} }}", float(*x))
                }
            }
            Value::Raw(s) => s.clone(),
        }
    }
}
