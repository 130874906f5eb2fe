//! `atelier view DIR [--serve [PORT]]`: a finished run folder as a web page (docs/viewer.md).
//!
//! The page is a fixed set of assets (`crates/cli/assets/viewer/`: the page, one classic-script
//! bundle of three.js and the viewer, its style sheet and three.js's licence), built by
//! `crates/cli/viewer/build.sh` and embedded here, plus one file written per run,
//! `viewer-data.js`, which carries the run itself: `report.json`, `run.glb` (base64) and
//! `series.csv`. A browser opening `index.html` from the disk refuses `fetch` and module scripts,
//! so the data arrives as a classic script and the page works from the files alone.
//!
//! What is missing or broken (no `report.json`, no `run.glb`, a glTF binary whose header or JSON
//! chunk does not read) is said twice: by the command, one line each on stderr, and by the page,
//! which shows what it could load and names what it could not. Every file is written atomically.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};

use atelier::run::outputs;
use serde_json::{Value, json};

/// The page's fixed files, embedded at build time (`assets/viewer/FILES` lists the same names).
const ASSETS: [(&str, &[u8]); 4] = [
    ("index.html", include_bytes!("../assets/viewer/index.html")),
    ("viewer.js", include_bytes!("../assets/viewer/viewer.js")),
    ("viewer.css", include_bytes!("../assets/viewer/viewer.css")),
    (
        "THREE-LICENSE.txt",
        include_bytes!("../assets/viewer/THREE-LICENSE.txt"),
    ),
];

/// The file the run's data goes into.
pub const DATA: &str = "viewer-data.js";

/// Why the page could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// The folder does not exist or is not a folder.
    #[error("{}: not a run folder (it does not exist or is not a folder)", .0.display())]
    NotAFolder(PathBuf),
    /// A file could not be written.
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// What [`write_page`] wrote and what it found missing or broken.
#[derive(Debug)]
pub struct Page {
    /// The page to open.
    pub index: PathBuf,
    /// One sentence per missing or broken input (the page shows the same).
    pub problems: Vec<String>,
}

/// Write the page of the run folder `dir`: the assets and `viewer-data.js`.
pub fn write_page(dir: &Path) -> Result<Page, ViewError> {
    if !dir.is_dir() {
        return Err(ViewError::NotAFolder(dir.to_path_buf()));
    }
    let mut problems = Vec::new();
    let report = match std::fs::read_to_string(dir.join(outputs::REPORT)) {
        Ok(text) => match serde_json::from_str::<Value>(&text) {
            Ok(v) => Some(v),
            Err(e) => {
                problems.push(format!("{} is not valid JSON: {e}", outputs::REPORT));
                None
            }
        },
        Err(e) => {
            problems.push(missing(outputs::REPORT, &e));
            None
        }
    };
    let glb = match std::fs::read(dir.join(outputs::GLB)) {
        Ok(bytes) => match check_glb(&bytes) {
            Ok(()) => Some(base64(&bytes)),
            Err(why) => {
                problems.push(format!(
                    "{} is not a readable glTF binary: {why}",
                    outputs::GLB
                ));
                None
            }
        },
        Err(e) => {
            problems.push(missing(outputs::GLB, &e));
            None
        }
    };
    let series = std::fs::read_to_string(dir.join(outputs::SERIES)).ok();
    let data = json!({
        "report": report,
        "glb": glb,
        "series": series,
        "problems": problems,
    });
    let script = format!("window.ATELIER_RUN = {data};\n");
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        atelier_files::files::write_atomic(&path, bytes)
            .map_err(|source| ViewError::Write { path, source })
    };
    for (name, bytes) in ASSETS {
        write(name, bytes)?;
    }
    write(DATA, script.as_bytes())?;
    Ok(Page {
        index: dir.join("index.html"),
        problems,
    })
}

fn missing(name: &str, e: &std::io::Error) -> String {
    if e.kind() == std::io::ErrorKind::NotFound {
        format!("{name} is missing (the run did not finish, or this is not a run folder)")
    } else {
        format!("{name} cannot be read: {e}")
    }
}

/// Check a glTF binary's header (magic, version 2, length), its JSON chunk (it parses and
/// holds meshes) and that the binary chunk is as long as the JSON says.
fn check_glb(bytes: &[u8]) -> Result<(), String> {
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(magic), Some(version), Some(length)) = (word(0), word(4), word(8)) else {
        return Err(format!(
            "{} bytes, shorter than its 12-byte header",
            bytes.len()
        ));
    };
    if magic != 0x4654_6C67 {
        return Err("it does not start with the glTF magic `glTF`".into());
    }
    if version != 2 {
        return Err(format!("version {version}, not 2"));
    }
    if length as usize != bytes.len() {
        return Err(format!(
            "its header says {length} bytes, the file has {} (cut short?)",
            bytes.len()
        ));
    }
    let (Some(json_len), Some(kind)) = (word(12), word(16)) else {
        return Err("no JSON chunk".into());
    };
    if kind != 0x4E4F_534A {
        return Err("its first chunk is not JSON".into());
    }
    let json_bytes = bytes
        .get(20..20 + json_len as usize)
        .ok_or("its JSON chunk runs past the end of the file")?;
    let doc: Value = serde_json::from_slice(json_bytes)
        .map_err(|e| format!("its JSON chunk does not parse: {e}"))?;
    if doc["meshes"].as_array().is_none_or(Vec::is_empty) {
        return Err("it holds no mesh".into());
    }
    let needed = doc["buffers"][0]["byteLength"].as_u64().unwrap_or(0);
    let bin_at = 20 + json_len as usize;
    let bin_len = word(bin_at).unwrap_or(0) as u64;
    if bin_len < needed {
        return Err(format!(
            "its binary chunk holds {bin_len} bytes, the JSON needs {needed}"
        ));
    }
    Ok(())
}

/// Standard base64 (RFC 4648, with padding).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Serve the folder `dir` on 127.0.0.1:`port` (0: any free port) until the process is stopped;
/// `ready` receives the address once the socket listens. Only GET of a file directly in `dir`
/// is answered; anything else is 404 (no other folder is ever read).
pub fn serve(dir: &Path, port: u16, ready: impl FnOnce(&str)) -> std::io::Result<()> {
    let listener = TcpListener::bind(("127.0.0.1", port))?;
    let address = format!("http://{}/", listener.local_addr()?);
    ready(&address);
    for stream in listener.incoming() {
        // A client that goes away mid-request changes nothing for the next one.
        let _ = stream.and_then(|s| answer(dir, s));
    }
    Ok(())
}

fn answer(dir: &Path, mut stream: TcpStream) -> std::io::Result<()> {
    let mut request = String::new();
    let mut reader = BufReader::new(&stream);
    reader.read_line(&mut request)?;
    // Read the headers to their blank line, so that the client has sent its whole request
    // before the answer closes the connection.
    let mut header = String::new();
    while reader.read_line(&mut header)? > 2 {
        header.clear();
    }
    let mut words = request.split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    let name = target
        .split(['?', '#'])
        .next()
        .unwrap_or("")
        .trim_start_matches('/');
    let name = if name.is_empty() { "index.html" } else { name };
    let safe = !name.contains(['/', '\\']) && !name.starts_with('.');
    let file = (method == "GET" && safe)
        .then(|| std::fs::File::open(dir.join(name)).ok())
        .flatten();
    let Some(mut file) = file else {
        let body = b"not found";
        write!(
            stream,
            "HTTP/1.1 404 Not Found\r\nContent-Type: text/plain\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
            body.len()
        )?;
        return stream.write_all(body);
    };
    let mut body = Vec::new();
    file.read_to_end(&mut body)?;
    write!(
        stream,
        "HTTP/1.1 200 OK\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        content_type(name),
        body.len()
    )?;
    stream.write_all(&body)
}

fn content_type(name: &str) -> &'static str {
    match name.rsplit('.').next().unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "json" => "application/json",
        "glb" => "model/gltf-binary",
        "png" => "image/png",
        "csv" | "txt" | "ron" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_test_vectors() {
        // RFC 4648 §10.
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, encoded) in cases {
            assert_eq!(base64(plain.as_bytes()), encoded, "{plain:?}");
        }
    }

    #[test]
    fn the_asset_list_is_the_committed_files_list() {
        let listed = include_str!("../assets/viewer/FILES");
        let listed: Vec<&str> = listed
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        let embedded: Vec<&str> = ASSETS.iter().map(|(n, _)| *n).collect();
        assert_eq!(listed, embedded);
    }

    fn run_folder(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("atelier-view-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_folder_without_its_files_gets_a_page_naming_what_is_missing() {
        let dir = run_folder("empty");
        let page = write_page(&dir).unwrap();
        assert!(page.index.is_file());
        assert_eq!(page.problems.len(), 2, "{:?}", page.problems);
        assert!(page.problems[0].starts_with("report.json is missing"));
        assert!(page.problems[1].starts_with("run.glb is missing"));
        let data = std::fs::read_to_string(dir.join(DATA)).unwrap();
        let json = data
            .strip_prefix("window.ATELIER_RUN = ")
            .and_then(|s| s.trim_end().strip_suffix(';'))
            .unwrap();
        let v: Value = serde_json::from_str(json).unwrap();
        assert!(v["glb"].is_null() && v["report"].is_null());
        assert_eq!(v["problems"].as_array().unwrap().len(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_broken_glb_and_report_are_named_and_not_embedded() {
        let dir = run_folder("broken");
        std::fs::write(dir.join("report.json"), "{\"format\": ").unwrap();
        // A header that claims more bytes than the file holds (a copy cut short).
        let mut glb = Vec::new();
        for w in [0x4654_6C67u32, 2, 4096] {
            glb.extend_from_slice(&w.to_le_bytes());
        }
        std::fs::write(dir.join("run.glb"), &glb).unwrap();
        let page = write_page(&dir).unwrap();
        assert!(page.problems[0].starts_with("report.json is not valid JSON"));
        assert!(page.problems[1].contains("header says 4096 bytes, the file has 12"));
        std::fs::write(dir.join("run.glb"), b"PK\x03\x04 a zip, not glTF").unwrap();
        let page = write_page(&dir).unwrap();
        assert!(
            page.problems[1].contains("glTF magic"),
            "{:?}",
            page.problems
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_folder_is_an_error() {
        let dir = std::env::temp_dir().join("atelier-view-no-such-folder");
        assert!(matches!(write_page(&dir), Err(ViewError::NotAFolder(_))));
    }

    #[test]
    fn the_server_answers_files_of_the_folder_and_nothing_outside_it() {
        let dir = run_folder("serve");
        std::fs::write(dir.join("index.html"), "<p>run</p>").unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        let served = dir.clone();
        std::thread::spawn(move || serve(&served, 0, |a| tx.send(a.to_string()).unwrap()));
        let address = rx.recv().unwrap();
        let host = address
            .trim_start_matches("http://")
            .trim_end_matches('/')
            .to_string();
        let get = |path: &str| {
            let mut s = TcpStream::connect(&host).unwrap();
            write!(s, "GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n").unwrap();
            let mut text = String::new();
            s.read_to_string(&mut text).unwrap();
            text
        };
        let index = get("/");
        assert!(index.starts_with("HTTP/1.1 200"), "{index}");
        assert!(index.contains("text/html") && index.ends_with("<p>run</p>"));
        assert!(get("/../Cargo.toml").starts_with("HTTP/1.1 404"));
        assert!(get("/%2e%2e/x").starts_with("HTTP/1.1 404"));
        assert!(get("/.viewer-data.tmp-1").starts_with("HTTP/1.1 404"));
        assert!(get("/nothing.js").starts_with("HTTP/1.1 404"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
