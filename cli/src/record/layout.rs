//! A viewer layout (Rerun blueprint) written archetype by archetype.
//!
//! Rerun 0.36.3's Rust builders (`rerun::blueprint::TimeSeriesView`, ...)
//! cannot set a view's properties (the plot legend, the time axis, the 2D
//! view's visual bounds); only the Python SDK can. This module writes the
//! same blueprint entities the builders write (`container/<id>`,
//! `view/<id>`, `view/<id>/ViewContents`, `viewport`, the panels) plus the
//! properties under `view/<id>/<archetype>` (`view/<id>/PlotLegend`), where
//! the viewer reads them. Ids are numbered, so two recordings of a scene
//! carry the same layout.

use rerun::blueprint::components::{
    ColumnShare, ContainerKind, IncludedContent, PanelState, PlayState, QueryExpression,
    RootContainer, RowShare, TimelineName, ViewClass,
};
use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg, RecordingId};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, PanelBlueprint, TimePanelBlueprint, ViewBlueprint, ViewContents,
    ViewportBlueprint,
};
use rerun::{AsComponents, RecordingStream, RecordingStreamBuilder, SerializedComponentBatch};

/// A container or a view.
pub enum Node {
    Container(Container),
    View(View),
}

/// Views or containers side by side (`Horizontal`) or stacked (`Vertical`).
pub struct Container {
    pub kind: ContainerKind,
    pub children: Vec<Node>,
    /// Relative widths of the children (horizontal containers).
    pub column_shares: Vec<f32>,
    /// Relative heights of the children (vertical containers).
    pub row_shares: Vec<f32>,
}

impl Container {
    pub fn horizontal(children: Vec<Node>, column_shares: Vec<f32>) -> Node {
        Node::Container(Container {
            kind: ContainerKind::Horizontal,
            children,
            column_shares,
            row_shares: Vec::new(),
        })
    }

    pub fn vertical(children: Vec<Node>, row_shares: Vec<f32>) -> Node {
        Node::Container(Container {
            kind: ContainerKind::Vertical,
            children,
            column_shares: Vec::new(),
            row_shares,
        })
    }
}

/// One view: its class (`"TimeSeries"`, `"2D"`, `"3D"`, `"TextDocument"`),
/// title, origin, contents and properties.
pub struct View {
    pub class: &'static str,
    pub name: String,
    pub origin: String,
    /// Query expressions; `$origin/**` when empty.
    pub contents: Vec<String>,
    /// `(archetype name, its fields)`, logged at `view/<id>/<archetype name>`.
    pub properties: Vec<(&'static str, Vec<SerializedComponentBatch>)>,
}

impl View {
    pub fn new(class: &'static str, name: impl Into<String>, origin: impl Into<String>) -> Self {
        View {
            class,
            name: name.into(),
            origin: origin.into(),
            contents: Vec::new(),
            properties: Vec::new(),
        }
    }

    /// Sets a view property (`PlotLegend`, `TimeAxis`, `VisualBounds2D`, ...).
    pub fn with_property(mut self, name: &'static str, archetype: &dyn AsComponents) -> Self {
        self.properties
            .push((name, archetype.as_serialized_batches()));
        self
    }

    pub fn with_contents(mut self, queries: &[&str]) -> Self {
        self.contents = queries.iter().map(|q| q.to_string()).collect();
        self
    }
}

impl From<View> for Node {
    fn from(v: View) -> Self {
        Node::View(v)
    }
}

/// The whole layout: the views and the state of the side panels.
pub struct Layout {
    pub root: Node,
    pub blueprint_panel: PanelState,
    pub selection_panel: PanelState,
    pub time_panel: PanelState,
    /// The timeline the time panel shows.
    pub timeline: &'static str,
    /// Whether time plays from the start or follows the latest data.
    pub play_state: PlayState,
}

/// A deterministic UUID (version 4 layout) for the `n`-th node.
fn uuid(n: u64) -> [u8; 16] {
    let mut b = [0u8; 16];
    b[..4].copy_from_slice(b"yarn");
    b[6] = 0x40;
    b[8] = 0x80;
    b[10..].copy_from_slice(&n.to_be_bytes()[2..]);
    b
}

/// `8-4-4-4-12` lower-case hex, as the viewer parses ids from paths.
fn uuid_text(b: &[u8; 16]) -> String {
    let h: Vec<String> = b.iter().map(|x| format!("{x:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        h[..4].concat(),
        h[4..6].concat(),
        h[6..8].concat(),
        h[8..10].concat(),
        h[10..].concat()
    )
}

impl Layout {
    /// The blueprint's messages, as `Blueprint::send` makes them.
    fn messages(&self, app_id: &'static str) -> rerun::RecordingStreamResult<Vec<LogMsg>> {
        let (bp, storage) = RecordingStreamBuilder::new(app_id)
            .recording_id(RecordingId::random())
            .blueprint()
            .memory()?;
        // The viewer identifies blueprint data by this timeline.
        bp.set_time_sequence("blueprint", 0);
        let mut next = 0;
        let root = log_node(&bp, &self.root, &mut next)?;
        bp.log(
            "viewport",
            &ViewportBlueprint::new()
                .with_root_container(RootContainer(rerun::datatypes::Uuid { bytes: root.1 })),
        )?;
        bp.log(
            "blueprint_panel",
            &PanelBlueprint::new().with_state(self.blueprint_panel),
        )?;
        bp.log(
            "selection_panel",
            &PanelBlueprint::new().with_state(self.selection_panel),
        )?;
        bp.log(
            "time_panel",
            &TimePanelBlueprint::new()
                .with_state(self.time_panel)
                .with_timeline(TimelineName::from(self.timeline))
                .with_play_state(self.play_state),
        )?;
        Ok(storage.take())
    }

    /// Sends the layout to `rec`, active and the app's default.
    pub fn send(
        &self,
        rec: &RecordingStream,
        app_id: &'static str,
    ) -> rerun::RecordingStreamResult<()> {
        let msgs = self.messages(app_id)?;
        let Some(LogMsg::SetStoreInfo(info)) = msgs.first() else {
            // A memory stream starts with its store info.
            return Ok(());
        };
        let blueprint_id = info.info.store_id.clone();
        rec.send_blueprint(
            msgs,
            BlueprintActivationCommand {
                blueprint_id,
                make_active: true,
                make_default: true,
            },
        );
        Ok(())
    }
}

/// Logs `node` and what it contains; returns its blueprint path and id.
fn log_node(
    bp: &RecordingStream,
    node: &Node,
    next: &mut u64,
) -> rerun::RecordingStreamResult<(String, [u8; 16])> {
    let id = uuid(*next);
    *next += 1;
    match node {
        Node::View(v) => {
            let path = format!("view/{}", uuid_text(&id));
            let contents: Vec<String> = if v.contents.is_empty() {
                vec!["$origin/**".into()]
            } else {
                v.contents.clone()
            };
            bp.log(
                format!("{path}/ViewContents"),
                &ViewContents::new(contents.into_iter().map(|q| QueryExpression(q.into()))),
            )?;
            bp.log(
                path.as_str(),
                &ViewBlueprint::new(ViewClass(v.class.into()))
                    .with_display_name(v.name.as_str())
                    .with_space_origin(v.origin.as_str()),
            )?;
            for (name, batches) in &v.properties {
                bp.log_serialized_batches(
                    format!("{path}/{name}"),
                    false,
                    batches.iter().cloned(),
                )?;
            }
            Ok((path, id))
        }
        Node::Container(c) => {
            let mut children = Vec::new();
            for child in &c.children {
                children.push(log_node(bp, child, next)?.0);
            }
            let path = format!("container/{}", uuid_text(&id));
            let mut arch = ContainerBlueprint::new(c.kind)
                .with_contents(children.iter().map(|p| IncludedContent(p.as_str().into())));
            if !c.column_shares.is_empty() {
                arch = arch.with_col_shares(c.column_shares.iter().map(|&s| ColumnShare(s.into())));
            }
            if !c.row_shares.is_empty() {
                arch = arch.with_row_shares(c.row_shares.iter().map(|&s| RowShare(s.into())));
            }
            bp.log(path.as_str(), &arch)?;
            Ok((path, id))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_uuid_text() {
        assert_eq!(uuid_text(&uuid(0)), "7961726e-0000-4000-8000-000000000000");
        assert_eq!(
            uuid_text(&uuid(258)),
            "7961726e-0000-4000-8000-000000000102"
        );
    }
}
