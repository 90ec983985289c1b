//! Reading a frame's header attributes back, for tests and tools: the
//! standard attributes the exr crate keeps in fields of their own and every
//! other one, by name (docs/output.md, "Header attributes").

use std::path::Path;

use exr::meta::attribute::AttributeValue;

use crate::error::Error;

/// The header attributes of a file, for tests and tools: (name, value).
pub fn read_attributes(path: &Path) -> Result<Vec<(String, AttributeValue)>, Error> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| Error::Read {
        path: path.to_path_buf(),
        problem: e.to_string(),
    })?;
    let mut out = Vec::new();
    for h in &meta.headers {
        let own = &h.own_attributes;
        if let Some(s) = &own.software_name {
            out.push(("software".to_string(), AttributeValue::Text(s.clone())));
        }
        if let Some(d) = &own.capture_date {
            out.push(("capDate".to_string(), AttributeValue::Text(d.clone())));
        }
        if let Some(o) = own.utc_offset {
            out.push(("utcOffset".to_string(), AttributeValue::F32(o)));
        }
        for (name, m) in [
            ("worldToCamera", own.world_to_camera),
            ("worldToNDC", own.world_to_normalized_device),
        ] {
            if let Some(m) = m {
                out.push((name.to_string(), AttributeValue::Matrix4x4(m)));
            }
        }
        for (k, v) in h
            .own_attributes
            .other
            .iter()
            .chain(&h.shared_attributes.other)
        {
            out.push((k.to_string(), v.clone()));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// The string attribute `name` of `attributes`, if present.
pub fn text_attribute(attributes: &[(String, AttributeValue)], name: &str) -> Option<String> {
    attributes
        .iter()
        .find(|a| a.0 == name)
        .and_then(|a| match &a.1 {
            AttributeValue::Text(t) => String::from_utf8(t.bytes().to_vec()).ok(),
            _ => None,
        })
}
