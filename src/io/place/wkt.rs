//! Well-known text (WKT1, ESRI WKT and WKT2) of `.prj` files and GeoTIFF
//! PE strings: read far enough to know the CRS's kind, name, EPSG code and
//! linear unit; and written for the EPSG codes whose definition we carry.
//!
//! Reading parses the bracket tree (`NAME[arg, ...]`, `(` `)` accepted too)
//! with a depth and size limit, then looks at the root: `GEOGCS` / `GEOGCRS`
//! / `GEODCRS` are geographic (degrees), `PROJCS` / `PROJCRS` projected, with
//! the unit from the root's `UNIT` / `LENGTHUNIT` (WKT1) or the last
//! `LENGTHUNIT` in an axis (WKT2). The EPSG code comes from the root's
//! `AUTHORITY["EPSG", "n"]` or `ID["EPSG", n]`, else from a table of the
//! names ESRI and EPSG give the common DEM CRSs (WGS 84, NAD83, ETRS89 and
//! their UTM zones) — GDAL's own ESRI `.prj` files carry no authority.
//!
//! Writing: WKT1 with a root `AUTHORITY` (so GDAL identifies the EPSG code)
//! for geographic WGS 84 (4326), NAD83 (4269), ETRS89 (4258) and the UTM
//! zones on them (326zz / 327zz, 269zz, 258zz). Other codes have no WKT
//! here: [`for_epsg`] returns `None` and the caller says so.

use crate::georef::{Crs, Units};

/// The most nesting and the most nodes a WKT may have (real ones: depth ≤ 8,
/// a few hundred nodes).
const MAX_DEPTH: usize = 32;
const MAX_NODES: usize = 10_000;

#[derive(Debug)]
enum Node {
    Text(String),
    Word(String),
    Tree(String, Vec<Node>),
}

impl Node {
    fn keyword(&self) -> Option<(&str, &[Node])> {
        match self {
            Node::Tree(k, a) => Some((k, a)),
            _ => None,
        }
    }
    fn text(&self) -> Option<&str> {
        match self {
            Node::Text(s) | Node::Word(s) => Some(s),
            Node::Tree(..) => None,
        }
    }
}

struct Parser<'a> {
    s: &'a [u8],
    pos: usize,
    nodes: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self
            .s
            .get(self.pos)
            .is_some_and(|b| b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
    }

    fn node(&mut self, depth: usize) -> Result<Node, String> {
        self.nodes += 1;
        if depth > MAX_DEPTH || self.nodes > MAX_NODES {
            return Err(format!(
                "nested deeper than {MAX_DEPTH} or more than {MAX_NODES} elements"
            ));
        }
        self.skip_ws();
        match self.s.get(self.pos) {
            None => Err("ends early".into()),
            Some(b'"') => {
                self.pos += 1;
                let mut out = Vec::new();
                loop {
                    match self.s.get(self.pos) {
                        None => return Err("a quoted name is not closed".into()),
                        // WKT escapes a quote by doubling it.
                        Some(b'"') if self.s.get(self.pos + 1) == Some(&b'"') => {
                            out.push(b'"');
                            self.pos += 2;
                        }
                        Some(b'"') => {
                            self.pos += 1;
                            break;
                        }
                        Some(&b) => {
                            out.push(b);
                            self.pos += 1;
                        }
                    }
                }
                Ok(Node::Text(String::from_utf8_lossy(&out).into_owned()))
            }
            Some(_) => {
                let start = self.pos;
                while self.s.get(self.pos).is_some_and(|&b| {
                    !b.is_ascii_whitespace() && !matches!(b, b'[' | b']' | b'(' | b')' | b',')
                }) {
                    self.pos += 1;
                }
                if self.pos == start {
                    return Err(format!("unexpected {:?}", self.s[start] as char));
                }
                let word = String::from_utf8_lossy(&self.s[start..self.pos]).into_owned();
                self.skip_ws();
                let close = match self.s.get(self.pos) {
                    Some(b'[') => b']',
                    Some(b'(') => b')',
                    _ => return Ok(Node::Word(word)),
                };
                self.pos += 1;
                let mut args = Vec::new();
                loop {
                    self.skip_ws();
                    if self.s.get(self.pos) == Some(&close) && args.is_empty() {
                        self.pos += 1;
                        break;
                    }
                    args.push(self.node(depth + 1)?);
                    self.skip_ws();
                    match self.s.get(self.pos) {
                        Some(b',') => self.pos += 1,
                        Some(&c) if c == close => {
                            self.pos += 1;
                            break;
                        }
                        Some(&c) => {
                            return Err(format!(
                                "expected ',' or a closing bracket, found {:?}",
                                c as char
                            ));
                        }
                        None => return Err("a bracket is not closed".into()),
                    }
                }
                Ok(Node::Tree(word.to_ascii_uppercase(), args))
            }
        }
    }
}

/// Reads the CRS a WKT describes. The error says what is wrong with it.
pub fn parse(text: &[u8]) -> Result<Crs, String> {
    let text = text.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(text);
    let mut p = Parser {
        s: text,
        pos: 0,
        nodes: 0,
    };
    let root = p.node(0)?;
    p.skip_ws();
    if p.pos != text.len() {
        return Err(format!("unexpected text after the CRS at byte {}", p.pos));
    }
    let Some((kw, args)) = root.keyword() else {
        return Err("expected a CRS such as GEOGCS[...] or PROJCS[...]".into());
    };
    // A compound CRS: the horizontal part is the first CRS in it.
    if matches!(kw, "COMPD_CS" | "COMPOUNDCRS") {
        let inner = args
            .iter()
            .find(|n| n.keyword().is_some())
            .ok_or("a compound CRS without parts")?;
        let mut out = crs_of(inner)?;
        out.wkt = Some(String::from_utf8_lossy(text).trim().to_string());
        return Ok(out);
    }
    let mut out = crs_of(&root)?;
    out.wkt = Some(String::from_utf8_lossy(text).trim().to_string());
    Ok(out)
}

fn crs_of(node: &Node) -> Result<Crs, String> {
    let (kw, args) = node.keyword().ok_or("expected a CRS")?;
    let geographic = match kw {
        "GEOGCS" | "GEOGCRS" | "GEODCRS" | "GEOGRAPHICCRS" | "GEODETICCRS" => true,
        "PROJCS" | "PROJCRS" | "PROJECTEDCRS" | "LOCAL_CS" | "ENGCRS" | "ENGINEERINGCRS" => false,
        other => {
            return Err(format!(
                "{other}[...] is not a horizontal CRS (expected GEOGCS, PROJCS, LOCAL_CS or their WKT2 forms)"
            ));
        }
    };
    let name = args.first().and_then(Node::text).map(str::to_string);
    let children = || args.iter().filter_map(Node::keyword);
    let authority = children()
        .filter(|(k, _)| matches!(*k, "AUTHORITY" | "ID"))
        .find_map(|(_, a)| {
            let auth = a.first()?.text()?;
            let code = a.get(1)?.text()?.trim().parse::<u32>().ok()?;
            auth.eq_ignore_ascii_case("EPSG").then_some(code)
        });
    let units = if geographic {
        Units::Degrees
    } else {
        let direct = args
            .iter()
            .filter_map(Node::keyword)
            .rfind(|(k, _)| matches!(*k, "UNIT" | "LENGTHUNIT"))
            .map(|(_, a)| a);
        let in_axis = || {
            let mut last = None;
            visit(node, &mut |k, a| {
                if k == "LENGTHUNIT" {
                    last = Some(a);
                }
            });
            last
        };
        let factor = direct
            .or_else(in_axis)
            .and_then(|a| a.get(1)?.text()?.trim().parse::<f64>().ok())
            .unwrap_or(1.0);
        if !(factor.is_finite() && factor > 0.0) {
            return Err(format!("linear unit factor {factor} is not > 0"));
        }
        Units::Linear {
            metres_per_unit: factor,
        }
    };
    let epsg = authority.or_else(|| name.as_deref().and_then(epsg_by_name));
    Ok(Crs {
        epsg,
        wkt: None,
        name,
        units,
        vertical_epsg: None,
    })
}

fn visit<'a>(node: &'a Node, f: &mut impl FnMut(&str, &'a [Node])) {
    if let Node::Tree(k, a) = node {
        f(k, a);
        for n in a {
            visit(n, f);
        }
    }
}

/// The geographic CRSs we can write: (EPSG, name, datum, ellipsoid, a, 1/f, ESRI names).
const GEOGRAPHIC: [(u32, &str, &str, &str, f64, f64, &str); 3] = [
    (
        4326,
        "WGS 84",
        "WGS_1984",
        "WGS 84",
        6378137.0,
        298.257223563,
        "GCS_WGS_1984",
    ),
    (
        4269,
        "NAD83",
        "North_American_Datum_1983",
        "GRS 1980",
        6378137.0,
        298.257222101,
        "GCS_North_American_1983",
    ),
    (
        4258,
        "ETRS89",
        "European_Terrestrial_Reference_System_1989",
        "GRS 1980",
        6378137.0,
        298.257222101,
        "GCS_ETRS_1989",
    ),
];

/// UTM zone families: (first EPSG code − 1, geographic base, north?, zones, ESRI prefix).
const UTM: [(u32, u32, bool, std::ops::RangeInclusive<u32>, &str); 4] = [
    (32600, 4326, true, 1..=60, "WGS_1984_UTM_Zone_"),
    (32700, 4326, false, 1..=60, "WGS_1984_UTM_Zone_"),
    (26900, 4269, true, 1..=23, "NAD_1983_UTM_Zone_"),
    (25800, 4258, true, 28..=38, "ETRS_1989_UTM_Zone_"),
];

/// (base, zone, north) of a UTM EPSG code we know.
fn utm(code: u32) -> Option<(u32, u32, bool)> {
    UTM.iter().find_map(|(first, base, north, zones, _)| {
        let z = code.checked_sub(*first)?;
        zones.contains(&z).then_some((*base, z, *north))
    })
}

fn epsg_by_name(name: &str) -> Option<u32> {
    let n = name.trim();
    if let Some(g) = GEOGRAPHIC
        .iter()
        .find(|g| n.eq_ignore_ascii_case(g.1) || n.eq_ignore_ascii_case(g.6))
    {
        return Some(g.0);
    }
    for (first, base, north, zones, esri) in UTM {
        let geo = GEOGRAPHIC.iter().find(|g| g.0 == base)?;
        let hemi = if north { 'N' } else { 'S' };
        let zone = if let Some(rest) = n.strip_prefix(esri) {
            rest.strip_suffix(hemi)
        } else {
            n.strip_prefix(geo.1)
                .and_then(|r| r.trim_start().strip_prefix("/ UTM zone "))
                .and_then(|r| r.strip_suffix(hemi))
        };
        if let Some(z) = zone.and_then(|z| z.parse::<u32>().ok())
            && zones.contains(&z)
        {
            return Some(first + z);
        }
    }
    None
}

fn geogcs(code: u32) -> Option<String> {
    let (c, name, datum, ell, a, rf, _) = GEOGRAPHIC.iter().find(|g| g.0 == code)?;
    Some(format!(
        "GEOGCS[\"{name}\",DATUM[\"{datum}\",SPHEROID[\"{ell}\",{a},{rf}]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433],AUTHORITY[\"EPSG\",\"{c}\"]]"
    ))
}

/// WKT1 for an EPSG code we carry the definition of, else `None`.
pub fn for_epsg(code: u32) -> Option<String> {
    if let Some(g) = geogcs(code) {
        return Some(g);
    }
    let (base, zone, north) = utm(code)?;
    let geo = GEOGRAPHIC.iter().find(|g| g.0 == base)?;
    let hemi = if north { "N" } else { "S" };
    let false_northing = if north { 0 } else { 10_000_000 };
    let meridian = zone as i32 * 6 - 183;
    Some(format!(
        "PROJCS[\"{} / UTM zone {zone}{hemi}\",{},PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",{meridian}],PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],PARAMETER[\"false_northing\",{false_northing}],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"{code}\"]]",
        geo.1,
        geogcs(base)?
    ))
}

/// Units of an EPSG code we know (degrees for the geographic ones, metres
/// for UTM), for readers that only have the code.
pub fn units_of(code: u32) -> Option<Units> {
    if GEOGRAPHIC.iter().any(|g| g.0 == code) {
        Some(Units::Degrees)
    } else {
        utm(code).map(|_| Units::Linear {
            metres_per_unit: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_gdal_esri_prj_and_wkt2() {
        // What gdal_translate -of AAIGrid writes for EPSG:32633 (no authority).
        let esri = br#"PROJCS["WGS_1984_UTM_Zone_33N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["False_Easting",500000.0],PARAMETER["False_Northing",0.0],PARAMETER["Central_Meridian",15.0],PARAMETER["Scale_Factor",0.9996],PARAMETER["Latitude_Of_Origin",0.0],UNIT["Meter",1.0]]"#;
        let c = parse(esri).unwrap();
        assert_eq!(c.epsg, Some(32633));
        assert_eq!(
            c.units,
            Units::Linear {
                metres_per_unit: 1.0
            }
        );
        let feet = br#"PROJCS["x",GEOGCS["y",DATUM["d",SPHEROID["s",1,1]],PRIMEM["G",0],UNIT["degree",0.01]],PROJECTION["p"],UNIT["US survey foot",0.304800609601219],AUTHORITY["EPSG","2227"]]"#;
        let c = parse(feet).unwrap();
        assert_eq!(c.epsg, Some(2227));
        assert!(
            matches!(c.units, Units::Linear { metres_per_unit } if (metres_per_unit - 0.3048006).abs() < 1e-6)
        );
        let wkt2 = br#"GEOGCRS["WGS 84",DATUM["World Geodetic System 1984",ELLIPSOID["WGS 84",6378137,298.257223563]],CS[ellipsoidal,2],AXIS["lat",north],AXIS["lon",east],ANGLEUNIT["degree",0.0174532925199433],ID["EPSG",4326]]"#;
        let c = parse(wkt2).unwrap();
        assert_eq!((c.epsg, c.units), (Some(4326), Units::Degrees));
    }

    #[test]
    fn written_wkt_reads_back_with_its_code() {
        for code in [4326, 4269, 4258, 32601, 32633, 32760, 26910, 25832] {
            let w = for_epsg(code).unwrap();
            let c = parse(w.as_bytes()).unwrap();
            assert_eq!(c.epsg, Some(code), "{w}");
            assert_eq!(Some(c.units), units_of(code));
        }
        assert!(for_epsg(3857).is_none());
        // UTM 33N: central meridian 15°E.
        assert!(
            for_epsg(32633)
                .unwrap()
                .contains("\"central_meridian\",15]")
        );
    }

    #[test]
    fn refuses_broken_text() {
        for bad in [
            &b""[..],
            b"GEOGCS[\"x\"",
            b"VERT_CS[\"h\"]",
            b"PROJCS[\"a\"] trailing",
            b"\"just a name\"",
        ] {
            assert!(parse(bad).is_err(), "{}", String::from_utf8_lossy(bad));
        }
        let deep = "A[".repeat(100);
        assert!(parse(deep.as_bytes()).unwrap_err().contains("deeper"));
    }
}
