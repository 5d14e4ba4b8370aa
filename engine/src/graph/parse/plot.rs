//! Reading `[[plot]]` tables.

use super::Ctx;
use crate::graph::model::Graph;
use crate::graph::plot::{Fit, PlotDecl};
use crate::suggest;
use toml::de::DeValue;
use toml::Spanned;

/// `[[plot]]`: an array of tables, each one figure.
pub(super) fn read_plots(cx: &mut Ctx<'_>, v: &Spanned<DeValue<'_>>, g: &mut Graph) {
    let DeValue::Array(items) = v.get_ref() else {
        let loc = cx.loc(v.span());
        cx.err(loc, None, "`plot` must be written as `[[plot]]` tables", None);
        return;
    };
    for item in items.iter() {
        let loc = cx.loc(item.span());
        let DeValue::Table(t) = item.get_ref() else {
            cx.err(loc, None, "`plot` must be written as `[[plot]]` tables", None);
            continue;
        };
        let mut p = PlotDecl {
            file: String::new(),
            title: String::new(),
            x: String::new(),
            y: Vec::new(),
            series: String::new(),
            log_x: false,
            log_y: false,
            fit: Fit::None,
            loc,
        };
        let mut ok = true;
        for (k, val) in t.iter() {
            let key = k.get_ref().as_ref();
            let at = cx.loc(k.span());
            let text = |v: &DeValue<'_>| v.as_str().map(str::to_string);
            match (key, val.get_ref()) {
                ("file" | "title" | "x" | "series", v) => match text(v) {
                    Some(s) => match key {
                        "file" => p.file = s,
                        "title" => p.title = s,
                        "x" => p.x = s,
                        _ => p.series = s,
                    },
                    None => {
                        cx.err(at, None, format!("plot `{key}` must be text"), None);
                        ok = false;
                    }
                },
                ("y", DeValue::String(s)) => p.y = vec![s.to_string()],
                ("y", DeValue::Array(a)) if a.iter().all(|e| e.get_ref().is_str()) && !a.is_empty() => {
                    p.y = a.iter().filter_map(|e| e.get_ref().as_str().map(str::to_string)).collect();
                }
                ("y", _) => {
                    cx.err(at, None, "plot `y` must be a quantity or a list of them", None);
                    ok = false;
                }
                ("log_x" | "log_y", DeValue::Boolean(b)) => {
                    if key == "log_x" {
                        p.log_x = *b;
                    } else {
                        p.log_y = *b;
                    }
                }
                ("log_x" | "log_y", _) => {
                    cx.err(at, None, format!("plot `{key}` must be true or false"), None);
                    ok = false;
                }
                ("fit", v) => match text(v).as_deref().and_then(Fit::from_name) {
                    Some(f) => p.fit = f,
                    None => {
                        let help = format!("one of {}", Fit::NAMES.join(", "));
                        cx.err(at, None, "plot `fit` is not a known fit", Some(help));
                        ok = false;
                    }
                },
                _ => {
                    let help = suggest::help(key, PlotDecl::KEYS);
                    cx.err(at, None, format!("unknown plot key `{key}`"), Some(help));
                    ok = false;
                }
            }
        }
        for (missing, empty) in [("file", p.file.is_empty()), ("x", p.x.is_empty()), ("y", p.y.is_empty())] {
            if empty {
                cx.err(loc, None, format!("plot without `{missing}`"), None);
                ok = false;
            }
        }
        if ok && !p.file.to_ascii_lowercase().ends_with(".png") {
            cx.err(loc, None, format!("plot file `{}` must end in .png", p.file), None);
            ok = false;
        }
        if ok {
            g.plots.push(p);
        }
    }
}
