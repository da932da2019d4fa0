"""The lab's side of ROS 2, without ROS: Eclipse Cyclone DDS from PyPI (the DDS behind
`rmw_cyclonedds`) speaking to tendril with ROS 2's topic prefixes, type names and CDR.

The message types are declared here as ROS 2's middleware registers them
(`sensor_msgs::msg::dds_::JointState_`, ...), field for field as in their `.msg` files.
Discovery stays on loopback: unicast to this machine's well-known ports, no multicast.
"""

import os
from dataclasses import dataclass

# Read by Cyclone DDS when the first participant is created: loopback only, unicast discovery
# of this machine's participants (as ROS_LOCALHOST_ONLY=1 does for a ROS 2 node).
os.environ["CYCLONEDDS_URI"] = (
    "<CycloneDDS><Domain Id='any'><General><Interfaces><NetworkInterface address='127.0.0.1'/>"
    "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
    "<Peers><Peer address='127.0.0.1'/></Peers><ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>30</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>"
)

from cyclonedds.core import Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.idl import IdlStruct  # noqa: E402
from cyclonedds.idl.types import float64, int32, sequence, uint32  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header
    name: sequence[str]
    position: sequence[float64]
    velocity: sequence[float64]
    effort: sequence[float64]


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64
    y: float64
    z: float64


@dataclass
class Wrench(IdlStruct, typename="geometry_msgs::msg::dds_::Wrench_"):
    force: Vector3
    torque: Vector3


@dataclass
class WrenchStamped(IdlStruct, typename="geometry_msgs::msg::dds_::WrenchStamped_"):
    header: Header
    wrench: Wrench


@dataclass
class Clock(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time


@dataclass
class FbgPeaks(IdlStruct, typename="tendril_msgs::msg::dds_::FbgPeaks_"):
    header: Header
    grating: sequence[str]
    wavelength_nm: sequence[float64]


@dataclass
class StringMsg(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str


#: ROS 2's default profile: reliable, volatile, keep last 10.
DEFAULT_QOS = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.Volatile, Policy.History.KeepLast(10))


class LabNode:
    """A participant in `domain` reading and writing ROS 2 topics by their ROS names."""

    def __init__(self, domain):
        self.participant = DomainParticipant(domain)
        self._topics = {}

    def _topic(self, name, msgtype):
        key = (name, msgtype)
        if key not in self._topics:
            self._topics[key] = Topic(self.participant, "rt" + name, msgtype, qos=DEFAULT_QOS)
        return self._topics[key]

    def reader(self, name, msgtype):
        return DataReader(self.participant, self._topic(name, msgtype), qos=DEFAULT_QOS)

    def writer(self, name, msgtype):
        return DataWriter(self.participant, self._topic(name, msgtype), qos=DEFAULT_QOS)


def stamp(t):
    """A `builtin_interfaces/Time` of `t` seconds."""
    sec = int(t)
    return Time(sec, int(round((t - sec) * 1e9)))


def as_seconds(time):
    return time.sec + time.nanosec * 1e-9
