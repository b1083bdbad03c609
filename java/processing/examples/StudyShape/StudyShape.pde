// The study of "Can You Feel My Sign?" (section 6): at what resolution can a person no longer
// tell the figure they feel? Sends a shape of the library at a chosen number of strokes.
// Keys: 1..6 choose the shape, + and - the number of strokes, Enter sends it, S stops.
import feelmysign.processing.*;
import feelmysign.shapes.Shapes;
import feelmysign.protocol.Stroke;
import java.util.List;

String BROKER = "mqtt://127.0.0.1:1883";
String USER = "sender";
String PASSWORD = "";   // from the broker's credentials.json
String SLEEVE = "sleeve1";
int ROWS = 3;           // the paper's sleeve: 3 x 4 actuators, 3 cm apart
int COLUMNS = 4;

String[] names = {"circle", "square", "triangle", "star", "heart", "line"};
int shape = 0;
int segments = 8;
FeelMySign sleeve;
List<Stroke> strokes;
String problem = "";

void setup() {
  size(800, 600);
  sleeve = new FeelMySign(this)
    .broker(BROKER)
    .login(USER, PASSWORD)
    .sleeve(SLEEVE)
    .set("rows", ROWS)
    .set("columns", COLUMNS)
    .start();
  choose(0, 0);
}

void choose(int next, int more) {
  shape = next;
  Shapes.Spec spec = Shapes.spec(names[shape]);
  segments = constrain(segments + more * spec.step(), spec.minSegments(), spec.maxSegments());
  segments = spec.minSegments() + (segments - spec.minSegments()) / spec.step() * spec.step();
  try {
    strokes = Shapes.strokes(names[shape], ROWS, COLUMNS, 3.0, 10000, segments, null, 0);
    problem = "";
  } catch (IllegalArgumentException e) {
    problem = e.getMessage();
  }
}

void draw() {
  background(255);
  strokeWeight(4);
  stroke(0);
  if (strokes != null) {
    for (Stroke s : strokes) {
      line(sleeve.canvasX(s.startX()), sleeve.canvasY(s.startY()),
           sleeve.canvasX(s.endX()), sleeve.canvasY(s.endY()));
    }
  }
  strokeWeight(8);
  stroke(30, 90, 220);
  sleeve.drawPlayed();
  fill(40);
  textSize(16);
  text(names[shape] + " of " + segments + " strokes  (1-6 shape, +/- strokes, Enter send, S stop)",
       12, 24);
  text(problem.length() > 0 ? problem : sleeve.status(), 12, height - 12);
}

void keyPressed() {
  if (key >= '1' && key <= '6') {
    choose(key - '1', 0);
  } else if (key == '+' || key == '=') {
    choose(shape, 1);
  } else if (key == '-') {
    choose(shape, -1);
  } else if ((key == ENTER || key == RETURN) && strokes != null) {
    sleeve.sendDrawing(strokes);
  } else if (key == 's' || key == 'S') {
    sleeve.stop();
  }
}
