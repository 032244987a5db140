//! Reading recordings back: Rerun's own decoder, chunks by entity path.

use std::collections::BTreeMap;
use std::io::BufReader;
use std::path::Path;

use rerun::external::re_log_encoding::DecoderApp;
use rerun::external::re_log_types::LogMsg;
use rerun::log::Chunk;
use rerun::StoreKind;

/// The chunks of one store of a recording (data or blueprint), by entity path.
pub fn decode_store(path: &Path, kind: StoreKind) -> BTreeMap<String, Vec<Chunk>> {
    let file = std::fs::File::open(path).expect("open rrd");
    let mut chunks: BTreeMap<String, Vec<Chunk>> = BTreeMap::new();
    for msg in DecoderApp::decode_eager(BufReader::new(file)).expect("rrd header") {
        let msg = msg.expect("decodable message");
        if let LogMsg::ArrowMsg(store, arrow) = &msg {
            if store.kind() != kind {
                continue;
            }
            let chunk = Chunk::from_arrow_msg(arrow).expect("chunk");
            chunks
                .entry(
                    chunk
                        .entity_path()
                        .to_string()
                        .trim_start_matches('/')
                        .to_string(),
                )
                .or_default()
                .push(chunk);
        }
    }
    chunks
}

/// Every value of component type `C` logged on these chunks, whatever its
/// archetype field.
pub fn all_values<C: rerun::Component + Clone>(chunks: &[Chunk]) -> Vec<C> {
    let mut out = Vec::new();
    for c in chunks {
        let ids: Vec<rerun::ComponentIdentifier> = c
            .component_descriptors()
            .filter(|d| d.component_type == Some(C::name()))
            .map(|d| d.component)
            .collect();
        for id in ids {
            for values in c.iter_component::<C>(id) {
                out.extend(values.iter().cloned());
            }
        }
    }
    out
}
