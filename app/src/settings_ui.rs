//! Settings panels drawn from the engine's one description of its settings
//! (`hush_engine::settings::fields`): each field gets the widget its kind calls for, its unit,
//! its help and default on hover, and a reset button when it differs from the default. Nothing
//! here names a particular field, so a new setting appears once it is described.

use hush_engine::settings::{Field, FrameSettings, Kind, fields, get_field, get_field_mut};
use serde_json::Value;

/// Short name of a field: the last part of its path.
fn name(f: &Field) -> &'static str {
    f.path.rsplit('.').next().unwrap_or(f.path)
}

fn show(v: &Value) -> String {
    match v {
        Value::Number(n) if n.is_f64() => format!("{:.4}", n.as_f64().unwrap_or(0.0))
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string(),
        Value::String(s) => s.clone(),
        v => v.to_string(),
    }
}

/// Which choices of a field the scene offers: (field path, choice) -> shown.
pub type Offered<'a> = &'a dyn Fn(&str, &str) -> bool;

/// One field's row; true when the value changed.
fn field_row(
    ui: &mut egui::Ui,
    f: &Field,
    value: &mut Value,
    default: &Value,
    offered: Offered,
) -> bool {
    let mut changed = false;
    let hover = format!(
        "{}\n{}: default {}{}",
        f.help.trim(),
        f.path,
        show(default),
        if f.unit.is_empty() { String::new() } else { format!(" {}", f.unit) }
    );
    ui.horizontal(|ui| {
        let r = match f.kind {
            Kind::Bool => {
                let mut b = value.as_bool().unwrap_or(false);
                let r = ui.checkbox(&mut b, name(f));
                if r.changed() {
                    *value = Value::Bool(b);
                }
                r
            }
            Kind::Int(lo, hi) => {
                let mut i = value.as_i64().unwrap_or(lo);
                let r = ui.add(egui::DragValue::new(&mut i).range(lo..=hi).speed(0.1));
                if r.changed() {
                    *value = Value::from(i);
                }
                ui.label(name(f));
                r
            }
            Kind::Float(lo, hi, speed) => {
                let mut x = value.as_f64().unwrap_or(lo);
                let r = ui
                    .add(egui::DragValue::new(&mut x).range(lo..=hi).speed(speed).max_decimals(4));
                if r.changed() {
                    *value = serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number);
                }
                ui.label(name(f));
                r
            }
            Kind::Choice(choices) => {
                let mut s = value.as_str().unwrap_or_default().to_string();
                let r = egui::ComboBox::from_id_salt(f.path).selected_text(&s).show_ui(ui, |ui| {
                    for c in choices().into_iter().filter(|c| offered(f.path, c)) {
                        ui.selectable_value(&mut s, c.clone(), c);
                    }
                });
                if value.as_str() != Some(s.as_str()) {
                    *value = Value::String(s);
                    changed = true;
                }
                ui.label(name(f));
                r.response
            }
        };
        changed |= r.changed();
        if !f.unit.is_empty() {
            ui.weak(f.unit);
        }
        r.on_hover_text(&hover);
        let differs = match (value.as_f64(), default.as_f64()) {
            (Some(a), Some(b)) => (a - b).abs() > 1e-6 * b.abs().max(1e-6),
            _ => value != default,
        };
        if differs
            && ui.small_button("↺").on_hover_text(format!("reset to {}", show(default))).clicked()
        {
            *value = default.clone();
            changed = true;
        }
    });
    changed
}

/// The fields of `group`; returns true when one changed. `v` is the settings' serde form.
pub fn group(
    ui: &mut egui::Ui,
    group: &str,
    v: &mut Value,
    defaults: &Value,
    offered: Offered,
) -> bool {
    let mut changed = false;
    for f in fields().filter(|f| f.group == group) {
        if let (Some(value), Some(default)) =
            (get_field_mut(v, f.path), get_field(defaults, f.path))
        {
            changed |= field_row(ui, f, value, default, offered);
        }
    }
    changed
}

/// The defaults' serde form, made once (the panel compares against it every frame).
pub fn defaults() -> &'static Value {
    static DEFAULTS: std::sync::OnceLock<Value> = std::sync::OnceLock::new();
    DEFAULTS.get_or_init(|| FrameSettings::default().to_value())
}

/// Groups in the order `fields()` lists them.
pub fn groups() -> Vec<&'static str> {
    let mut g: Vec<&'static str> = vec![];
    for f in fields() {
        if !g.contains(&f.group) {
            g.push(f.group);
        }
    }
    g
}

/// Apply an edited serde form; on a bad value the settings stay and the error is returned.
pub fn apply(settings: &mut FrameSettings, v: &Value) -> Result<(), String> {
    match FrameSettings::from_value(v) {
        Ok(s) => {
            *settings = s;
            Ok(())
        }
        Err(e) => Err(format!("{e:#}")),
    }
}
