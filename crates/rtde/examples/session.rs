//! An RTDE client and a controller session talking in memory: version, an output recipe, start,
//! one data package: `cargo run -p tendril-rtde --example session`.

use tendril_rtde::{ClientEvent, ClientSession, RobotOutputs, ServerConfig, ServerSession, SharedInputs};

/// Hands the client's packet bytes to the server and the server's replies back to the client.
fn exchange(
    client: &mut ClientSession,
    server: &mut ServerSession,
    shared: &mut SharedInputs,
    mut bytes: Vec<u8>,
) -> Vec<ClientEvent> {
    let mut reply = server.feed(&mut bytes, shared).expect("a valid request");
    client.feed(&mut reply).expect("a valid reply")
}

fn main() {
    let (mut client, mut server) = (ClientSession::new(), ServerSession::new(1, ServerConfig::default()));
    let mut shared = SharedInputs::new();
    let version = client.request_protocol_version().encode().unwrap();
    println!("{:?}", exchange(&mut client, &mut server, &mut shared, version));
    let setup = client.setup_outputs(500.0, &["timestamp", "actual_q"]).unwrap().encode().unwrap();
    println!("{:?}", exchange(&mut client, &mut server, &mut shared, setup));
    let start = client.start().encode().unwrap();
    println!("{:?}", exchange(&mut client, &mut server, &mut shared, start));
    // The controller's clock ticks: a data package is due every 2 ms.
    let outputs = RobotOutputs::default();
    for packet in server.poll_outputs(0.002, &outputs, &shared) {
        let mut bytes = packet.encode().unwrap();
        println!("{:?}", client.feed(&mut bytes).unwrap());
    }
}
