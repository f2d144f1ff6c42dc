// Names the dashboard uses for the generated contract types (src/generated/contracts.ts).
import type {
  Alert,
  ApiError,
  DroneCommand,
  GestureEvent,
  GestureProfile,
  TelemetryFrame,
  WsServerMessage,
} from './generated/contracts';
import { GESTURE_EVENT_GESTURE, DRONE_COMMAND_TYPE } from './generated/contracts';

export type * from './generated/contracts';

export type Gesture = GestureEvent['gesture'];
export type MappableGesture = Exclude<Gesture, 'NONE'>;
export type CommandType = DroneCommand['type'];
export type FlightState = TelemetryFrame['flight_state'];
export type Severity = Alert['severity'];
export type Mapping = NonNullable<GestureProfile['mappings'][MappableGesture]>;
export type ServerMessageType = WsServerMessage['type'];
export type { ApiError };

export const GESTURES: readonly Gesture[] = GESTURE_EVENT_GESTURE;
export const MAPPABLE_GESTURES: readonly MappableGesture[] = GESTURE_EVENT_GESTURE.filter(
  (g): g is MappableGesture => g !== 'NONE',
);
export const COMMAND_TYPES: readonly CommandType[] = DRONE_COMMAND_TYPE;
